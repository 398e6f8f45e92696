"""The package's error, apart from the modules that read files: the workflow's light commands
(`python3 -m floedem launch-one`, run once per job) import it without numpy or h5py."""


class FileError(ValueError):
    """A file that is not floedem's, of another format_version, or damaged: one line naming the
    file, the dataset and what was expected."""

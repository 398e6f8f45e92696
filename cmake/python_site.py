"""Prints where this Python looks for packages installed under PREFIX (argv[1]): the entry of
its module path under PREFIX (Debian: PREFIX/lib/python3.X/dist-packages for /usr/local), or
its user site when PREFIX is the user base (~/.local), else PREFIX/lib/python3.X/site-packages
(then on PYTHONPATH by hand: the install says so)."""
import os
import site
import sys
import sysconfig

prefix = os.path.realpath(os.path.abspath(sys.argv[1]))
for entry in sys.path:
    if entry and os.path.realpath(entry).startswith(prefix + os.sep) and entry.endswith("-packages"):
        print(entry)
        sys.exit(0)
if os.path.realpath(site.getuserbase()) == prefix:
    print(site.getusersitepackages())
    sys.exit(0)
local = sysconfig.get_path("purelib", "posix_prefix", vars={"base": prefix, "platbase": prefix})
print(local)

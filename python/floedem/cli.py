"""The Python half of `floedem export` and `floedem animate` (the floedem command runs it as
`python3 -m floedem ...`); usable alone the same way. Exit codes as the command's: 2 bad input,
3 the output cannot be written."""
import argparse
import sys

from .errors import FileError


def main(argv=None):
    ap = argparse.ArgumentParser(prog="floedem", description="floedem's results: export and films")
    sub = ap.add_subparsers(dest="command", required=True)
    ex = sub.add_parser("export", help="write a run as XDMF for ParaView (RUN.xdmf and RUN.xdmf.h5) or as GeoJSON "
                                       "for QGIS (RUN.geojson), beside it")
    ex.add_argument("run", help="a run's output, RESULT.h5")
    kind = ex.add_mutually_exclusive_group(required=True)
    kind.add_argument("--xdmf", action="store_true", help="XDMF for ParaView")
    kind.add_argument("--geojson", action="store_true", help="GeoJSON of a geographic scene's run: tracks and the "
                                                               "last frame's bodies in longitude and latitude")
    ex.add_argument("--out", "-o", help="the file (default: RESULT.xdmf or RESULT.geojson beside the run)")
    an = sub.add_parser("animate", help="write a film of a run (ffmpeg)")
    an.add_argument("run", help="a run's output, RESULT.h5")
    an.add_argument("--out", "-o", help="the film (default: RESULT.mp4 beside the run; .gif also works)")
    an.add_argument("--colour", choices=["speed", "force"], default="speed",
                    help="colour floes by speed, or by the contact force they carry (from /contacts)")
    an.add_argument("--fps", type=int, default=12, help="frames a second of film (default 12)")
    an.add_argument("--dpi", type=int, default=100, help="resolution (default 100)")
    an.add_argument("--quiet", "-q", action="store_true", help="no progress line")
    sw = sub.add_parser("sweep", help="run a sweep file through Snakemake and reduce it (docs/sweeps.md)")
    sw.add_argument("spec")
    sw.add_argument("--out", "-o", required=True)
    sw.add_argument("--floedem", default="floedem", help="the floedem command the runs use")
    sw.add_argument("--jobs", "-j", type=int)
    sw.add_argument("--profile")
    sw.add_argument("--dry-run", "-n", action="store_true")
    one = sub.add_parser("sweep-run", help="(the workflow's) one run of a sweep and its summary")
    one.add_argument("sweep_json")
    one.add_argument("id")
    lo = sub.add_parser("launch-one", help="(the workflow's) one job of a launch: run, record, report")
    lo.add_argument("launch_json")
    lo.add_argument("id")
    lo.add_argument("--threads", type=int, default=1)
    red = sub.add_parser("sweep-reduce", help="(the workflow's) the summaries of a sweep to reduced.csv and plots")
    red.add_argument("sweep_json")
    a = ap.parse_args(argv)
    target = getattr(a, "out", None) or getattr(a, "run", None)
    try:
        if a.command == "sweep":
            from .sweep import sweep
            target = a.out
            return sweep(a.spec, a.out, a.floedem, a.jobs, a.profile, a.dry_run)
        if a.command == "launch-one":
            from .launch import run_one as launch_one
            return launch_one(a.launch_json, a.id, a.threads)
        if a.command == "sweep-run":
            from .sweep import run_one
            return run_one(a.sweep_json, a.id)
        if a.command == "sweep-reduce":
            from .sweep import reduce
            reduce(a.sweep_json)
            return 0
        if a.command == "export" and a.geojson:
            from .geojson import export
            print(export(a.run, a.out))
        elif a.command == "export":
            from .xdmf import export
            print(export(a.run, a.out))
        else:
            from .animate import animate
            if a.fps < 1 or a.dpi < 10:
                raise FileError(f"--fps {a.fps}, --dpi {a.dpi}: allowed --fps >= 1 and --dpi >= 10")
            out = a.out or (a.run[:-3] if a.run.endswith(".h5") else a.run) + ".mp4"
            target = out
            print(animate(a.run, out, a.colour, a.fps, a.dpi, progress=not a.quiet))
    except (FileError, ValueError) as e:   # SweepError is a ValueError
        print(f"floedem: error: {e}", file=sys.stderr)
        return 2
    except OSError as e:
        print(f"floedem: output error: {target}: cannot write it ({e.strerror or e})", file=sys.stderr)
        return 3
    return 0


if __name__ == "__main__":
    sys.exit(main())

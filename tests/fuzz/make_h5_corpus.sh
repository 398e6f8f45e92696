#!/usr/bin/env bash
# Makes the seed corpus of the fuzz_h5 target, tests/fuzz/corpus/h5/*.h5.gz, with a built
# floedem: real outputs (a field file, a complete run, a run past its first checkpoint, a run
# killed mid-way) and damaged copies of them (h5py). Stored gzipped: a run's file is mostly
# the zeros of its preallocated chunks. scripts/fuzz.sh unpacks them.
#   tests/fuzz/make_h5_corpus.sh [build/floedem]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
floedem="${1:-$root/build/floedem}"
out="$root/tests/fuzz/corpus/h5"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
"$floedem" field --width 60 --height 40 --concentration 0.5 --alpha 2 --dmin 4 --dmax 15 --thickness 1 \
  --seed 3 -o "$work/field.h5" >/dev/null
"$floedem" run -q "$root/scenarios/head_on.toml" -o "$work/run.h5"
cat > "$work/two.toml" <<'TOML'
[run]
duration = 50.0
dt = 0.01
[[body]]
name = "a"
polygon = [[0, 0], [10, 0], [10, 10], [0, 10]]
thickness = 1.0
velocity = [0.2, 0.0]
[[body]]
name = "b"
polygon = [[20, 0], [30, 0], [20, 12]]
thickness = 1.0
TOML
"$floedem" run -q "$work/two.toml" -o "$work/checkpoint.h5"
FLOEDEM_TEST_KILL_AT_STEP=4500 "$floedem" run -q "$work/two.toml" -o "$work/killed.h5" || true
mv "$work/killed.h5.partial" "$work/killed.h5"
/usr/bin/python3 - "$work" <<'PY'
import shutil, sys
import h5py
import numpy as np
work = sys.argv[1]
def damaged(src, name, edit):
    path = f"{work}/{name}.h5"
    shutil.copy(f"{work}/{src}.h5", path)
    with h5py.File(path, "r+") as f:
        edit(f)
def negative_offset(f):
    o = f["/bodies/polygon_offsets"]; a = o[...]; a[1] = -5; o[...] = a
def flat_vertices(f):
    v = f["/bodies/polygon_vertices"][...].ravel(); del f["/bodies/polygon_vertices"]
    f["/bodies/polygon_vertices"] = v
def nan_velocity(f):
    d = f["/bodies/velocity"]; a = d[...]; a[-1, 0, 0] = np.nan; d[...] = a
def newer_format(f):
    f.attrs["format_version"] = np.int64(f.attrs["format_version"] + 1)
def negative_mass(f):
    d = f["/bodies/mass"]; a = d[...]; a[0] = -1.0; d[...] = a
damaged("field", "field_negative_offset", negative_offset)
damaged("field", "field_flat_vertices", flat_vertices)
damaged("run", "run_nan_velocity", nan_velocity)
damaged("run", "run_newer_format", newer_format)
damaged("checkpoint", "checkpoint_negative_mass", negative_mass)
PY
rm -rf "$out"
mkdir -p "$out"
for f in "$work"/*.h5; do gzip -9 -n -c "$f" > "$out/$(basename "$f").gz"; done
ls -l "$out"

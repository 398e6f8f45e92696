#!/usr/bin/env bash
# The installed package as a user meets it: installs the build into a temporary prefix, compiles
# each public header on its own against it, builds examples/ with find_package(floedem), and
# runs both examples from a directory of their own.
#   check_install.sh BUILD_DIR SOURCE_DIR WORK_DIR [CXX_FLAGS]
# CXX_FLAGS: for a sanitized build, the sanitizers (its library needs their runtime).
set -euo pipefail
build="$1" source="$2" work="$3" flags="${4:-}"
rm -rf "$work"
mkdir -p "$work"
prefix="$work/prefix"
cmake --install "$build" --prefix "$prefix" >/dev/null
[[ -x "$prefix/bin/floedem" && -f "$prefix/lib/cmake/floedem/floedemConfigVersion.cmake" ]]

# Each public header compiles alone (it includes what it uses, and nothing private).
mkdir -p "$work/headers"
{
  echo 'cmake_minimum_required(VERSION 3.25)'
  echo 'project(floedem_headers LANGUAGES CXX)'
  echo 'set(CMAKE_CXX_STANDARD 20)'
  echo 'find_package(floedem CONFIG REQUIRED)'
  echo 'add_library(headers OBJECT)'
  echo 'target_link_libraries(headers PRIVATE floedem::floedem)'
} > "$work/headers/CMakeLists.txt"
count=0
while IFS= read -r header; do
  rel="${header#"$prefix/include/"}"
  unit="$work/headers/$(echo "$rel" | tr '/.' '__').cpp"
  echo "#include <$rel>" > "$unit"
  echo "target_sources(headers PRIVATE $unit)" >> "$work/headers/CMakeLists.txt"
  count=$((count + 1))
done < <(find "$prefix/include/floedem" -name '*.hpp' | sort)
cmake -S "$work/headers" -B "$work/headers/build" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_CXX_FLAGS="-Wall -Werror $flags" >/dev/null
cmake --build "$work/headers/build" -j 2 >/dev/null
echo "install: $count public headers compile on their own"

cmake -S "$source/examples" -B "$work/examples" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_CXX_FLAGS="$flags" \
  -DCMAKE_EXE_LINKER_FLAGS="$flags" >/dev/null
cmake --build "$work/examples" -j 2 >/dev/null
mkdir -p "$work/run"
cd "$work/run"
"$work/examples/scene_in_code" "$work/run/scene.h5"
"$work/examples/own_engine"
echo "install: both examples built against $prefix and ran"

# The Python package: beside the command (floedem export runs it from there), and, for an
# install into the user base (the README's `--prefix ~/.local`), importable by python3 alone.
"$prefix/bin/floedem" export "$work/run/floe_floe_headon.native.h5" --xdmf >/dev/null
[[ -f "$work/run/floe_floe_headon.native.xdmf" ]]
python="${FLOEDEM_PYTHON:-/usr/bin/python3}"
PYTHONUSERBASE="$work/userbase" cmake --install "$build" --prefix "$work/userbase" >/dev/null
(cd "$work/run" && PYTHONUSERBASE="$work/userbase" "$python" -c \
  "import floedem, sys; r = floedem.open('floe_floe_headon.native.h5'); sys.exit(len(r.bodies) != 2)")
echo "install: the Python package imports from the user base and runs through the installed command"

#!/usr/bin/env bash
# The library as a user gets it (docs/library.md): installs BUILD_DIR into a temporary prefix and,
# from that prefix only (never the build tree), checks
#   1. every installed public header compiles on its own and names nothing from src/;
#   2. `bdptref --version` and bdptref.pc carry the project version; the installed suite loads;
#   3. a program built with `pkg-config --cflags --libs bdptref` links and runs;
#   4. examples/cpp-consumer: a separate CMake project, find_package(bdptref 7.0), its CTest tests
#      (shared and static library);
#   5. examples/pytest under the Debian /usr/bin/python3 with PYTHONPATH at the installed module
#      (pytest exit 5, "no tests collected", is a failure like any other).
# Usage: tools/ci/library-check.sh BUILD_DIR     (configured; the needed targets are built here)
set -euo pipefail
[ $# -eq 1 ] || { echo "usage: $0 BUILD_DIR" >&2; exit 2; }
src="$(cd "$(dirname "$0")/../.." && pwd)"
build="$(cd "$1" && pwd)"
py=/usr/bin/python3
start=$SECONDS
step() { echo "library-check [$((SECONDS - start)) s]: $*"; }
fail() { echo "library-check: FAILED: $*" >&2; exit 1; }

version=$(sed -n 's/^CMAKE_PROJECT_VERSION:STATIC=//p' "$build/CMakeCache.txt")
[ -n "$version" ] || fail "no CMAKE_PROJECT_VERSION in $build/CMakeCache.txt"
grep -q '^pybind11_DIR:PATH=/' "$build/CMakeCache.txt" || fail "pybind11 was not found when $build was configured (tools/install-deps.sh)"

step "building the installed targets in $build"
cmake --build "$build" --target bdptref bdptref_lib bdptref_shared bdptref_python >/dev/null

work=$(mktemp -d "${TMPDIR:-/tmp}/bdptref-library-check.XXXXXX")
trap 'rm -rf "$work"' EXIT
prefix="$work/prefix"
step "cmake --install $build --prefix $prefix"
cmake --install "$build" --prefix "$prefix" >/dev/null
libdir=$(sed -n 's/^CMAKE_INSTALL_LIBDIR:PATH=//p' "$build/CMakeCache.txt")
libdir=${libdir:-lib}
for f in include/bdptref/bdptref.h include/bdptref/version.h "$libdir/libbdptref.a" "$libdir/libbdptref.so.$version" \
         "$libdir/cmake/bdptref/bdptrefConfig.cmake" "$libdir/cmake/bdptref/bdptrefConfigVersion.cmake" \
         "$libdir/pkgconfig/bdptref.pc" bin/bdptref share/doc/bdptref/library.md; do
  [ -e "$prefix/$f" ] || fail "not installed: $f"
done
soname=$(objdump -p "$prefix/$libdir/libbdptref.so.$version" | awk '/SONAME/ {print $2}')
[ "$soname" = "libbdptref.so.${version%%.*}" ] || fail "SONAME is '$soname', expected libbdptref.so.${version%%.*}"

step "1. public headers: self-contained, nothing from src/"
if grep -nE '#include "(cli|core|scene|render|film|verify|wavefront|api)/' "$prefix"/include/bdptref/*.h; then
  fail "an installed header includes a private header from src/"
fi
ls "$prefix"/include/bdptref/*.h | xargs -P 2 -I{} sh -c \
  'echo "#include \"{}\"" | g++ -std=c++17 -fsyntax-only -Wall -Wextra -Wpedantic -Wshadow -Werror -I"$1" -x c++ - || { echo "not self-contained: {}" >&2; exit 255; }' \
  sh "$prefix/include" || fail "a public header does not compile on its own"

step "2. versions"
"$prefix/bin/bdptref" --version | grep -q "^bdptref $version " || fail "bdptref --version: $("$prefix/bin/bdptref" --version)"
# The installed conformance suite loads (its scenes, references, shapes and bug signatures): an
# unknown --scenes name is refused after the suite is read, listing its scenes.
suite_out=$("$prefix/bin/bdptref" validate --self path --scenes no-such-scene 2>&1 || true)
echo "$suite_out" | grep -q "it has: cornell-box" || fail "the installed suite does not load: $suite_out"
export PKG_CONFIG_PATH="$prefix/$libdir/pkgconfig"
[ "$(pkg-config --modversion bdptref)" = "$version" ] || fail "bdptref.pc version $(pkg-config --modversion bdptref)"

step "3. pkg-config build"
cat > "$work/pc.cpp" <<'CPP'
#include <bdptref/bdptref.h>
#include <cstdio>
int main() { std::printf("%s\n", bdptref::libraryVersion().text.c_str()); return bdptref::libraryVersion().text == BDPTREF_VERSION ? 0 : 1; }
CPP
# shellcheck disable=SC2046
g++ -std=c++17 "$work/pc.cpp" -o "$work/pc" $(pkg-config --cflags --libs bdptref) -Wl,-rpath,"$prefix/$libdir"
[ "$("$work/pc")" = "$version" ] || fail "the pkg-config program printed another version"

step "4. examples/cpp-consumer against $prefix"
cmake -S "$src/examples/cpp-consumer" -B "$work/consumer" -G Ninja -DCMAKE_PREFIX_PATH="$prefix" \
      -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF -DCMAKE_BUILD_TYPE=Release >"$work/consumer.log" 2>&1 \
  || { cat "$work/consumer.log"; fail "examples/cpp-consumer: configure"; }
found=$(sed -n 's/^bdptref_DIR:PATH=//p' "$work/consumer/CMakeCache.txt")
case "$found" in "$prefix"/*) ;; *) fail "examples/cpp-consumer found bdptref at '$found', not in $prefix" ;; esac
cmake --build "$work/consumer" >"$work/consumer.log" 2>&1 || { cat "$work/consumer.log"; fail "examples/cpp-consumer: build"; }
(cd "$work/consumer" && ctest --output-on-failure --no-tests=error) || fail "examples/cpp-consumer: tests"

step "5. examples/pytest under $py with the installed module"
pydir=$(sed -n 's/^BDPTREF_PYTHON_INSTALL_DIR:STRING=//p' "$build/CMakeCache.txt")
pypath="$prefix/${pydir:-lib/python3/dist-packages}"
where=$(PYTHONPATH="$pypath" "$py" -c 'import bdptref; print(bdptref.__file__)')
case "$where" in "$pypath"/*) ;; *) fail "import bdptref found $where, not the installed module" ;; esac
rc=0
(cd "$work" && PYTHONPATH="$pypath" PYTHONDONTWRITEBYTECODE=1 BDPTREF_SCENES="$src/scenes" PATH="/usr/bin:/bin" \
   "$py" -m pytest -p no:cacheprovider -q -rs "$src/examples/pytest") || rc=$?
[ "$rc" -eq 0 ] || fail "examples/pytest: pytest exit $rc (5 = no tests collected)"

step "passed"

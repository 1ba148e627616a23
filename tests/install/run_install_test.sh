#!/usr/bin/env bash
# Installs a built cadclash into a scratch prefix, builds examples/ against that prefix only (the
# CMake package), runs two examples and checks their output; then builds collide_only once more
# through pkg-config. Fails on any broken step: a missing header or library, a dependency the
# package config does not find, a link error, or wrong output.
#   run_install_test.sh <cadclash build dir> <cadclash source dir> <scratch dir>
set -euo pipefail
build=$1 src=$2 work=$3
prefix=$work/prefix
examples=$work/examples
rm -rf "$work"
mkdir -p "$work"

fail() { echo "FAIL: $*" >&2; exit 1; }
expect() {  # expect <output file> <fixed string>
  grep -qF -- "$2" "$1" || { cat "$1" >&2; fail "$(basename "$1") lacks: $2"; }
}

cmake --install "$build" --prefix "$prefix" > "$work/install.log"
for f in include/cadclash/collide.h include/cadclash/report.h include/cadclash/tessellate.h include/cadclash/import.h \
         include/cadclash/export.h include/cadclash/glb_layout.h lib/cmake/cadclash/cadclashConfig.cmake lib/pkgconfig/cadclash.pc; do
  [[ -f $prefix/$f ]] || fail "not installed: $f"
done
ls "$prefix"/lib/libcadclash_collide.* "$prefix"/lib/libcadclash_report.* "$prefix"/lib/libcadclash_tessellate.* \
   "$prefix"/lib/libcadclash_import.* "$prefix"/lib/libcadclash_export.* > /dev/null || fail "libraries not installed"
[[ -x $prefix/bin/cadclash ]] || fail "cadclash tool not installed"

# Only the scratch prefix may provide cadclash: no fallback to the build tree's package registry.
generator=()
command -v ninja > /dev/null && generator=(-G Ninja)
cmake -S "$src/examples" -B "$examples" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF > "$work/configure.log" \
  || { cat "$work/configure.log" >&2; fail "configuring examples/ against the package"; }
cmake --build "$examples" -j2 > "$work/build.log" 2>&1 \
  || { cat "$work/build.log" >&2; fail "building examples/ against the package"; }

# collide_only links cadclash::collide alone: two overlapping cubes, six crossing face pairs.
"$examples/collide_only/collide_only" > "$work/collide_only.out" || fail "collide_only exited non-zero"
expect "$work/collide_only.out" "6 colliding surface pairs"
expect "$work/collide_only.out" "/cube::1 +x <-> /cube::2 -y: penetrating"
if command -v ldd > /dev/null && ldd "$examples/collide_only/collide_only" | grep -qiE 'libTK|assimp'; then
  fail "collide_only pulls in OpenCASCADE or assimp"
fi

# list_surfaces on a real STEP assembly: paths with the file's own "::k", faces with their STEP #ids.
step=$src/data/external/as1-tu-203.stp
[[ -f $step ]] || fail "missing $step (run scripts/setup.sh)"
"$examples/list_surfaces/list_surfaces" "$step" > "$work/list_surfaces.out" || fail "list_surfaces exited non-zero"
expect "$work/list_surfaces.out" "5 parts, 18 instances, 53 surfaces"
expect "$work/list_surfaces.out" "/as1/L-BRACKET-ASSEMBLY::2/NUT-BOLT-ASSEMBLY::1/BOLT"
expect "$work/list_surfaces.out" "part 0: nut, 8 surfaces"
expect "$work/list_surfaces.out" "surface 0: face0, step-face #197"
"$examples/list_surfaces/list_surfaces" "$work/no-such-file.stp" > /dev/null 2>&1 \
  && fail "list_surfaces returned 0 for a missing file"

# pkg-config: the same collide example compiled and linked from cadclash.pc alone.
if command -v pkg-config > /dev/null; then
  export PKG_CONFIG_PATH=$prefix/lib/pkgconfig${PKG_CONFIG_PATH:+:$PKG_CONFIG_PATH}
  pkg-config --exists cadclash || fail "pkg-config does not find cadclash.pc"
  # shellcheck disable=SC2046
  ${CXX:-c++} -std=c++20 -O1 "$src/examples/collide_only/collide_only.cpp" -o "$work/collide_only_pc" \
    $(pkg-config --cflags cadclash) $(pkg-config --libs cadclash) || fail "building with pkg-config flags"
  "$work/collide_only_pc" | grep -qF "6 colliding surface pairs" || fail "pkg-config build gives wrong output"
fi
echo "install test passed: $prefix"

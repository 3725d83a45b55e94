#!/usr/bin/env bash
# Builds libg2p's Debian packages from debian/ (dpkg-buildpackage -b -us -uc),
# checks them with lintian (no error allowed), unpacks them into a throwaway
# root and runs what they installed from there: the consumer project against
# libg2p-dev (CMake package and pkg-config), `g2p run` from the g2p package with
# the models of libg2p-data, `import g2p` from python3-g2p, and Blender enabling
# the add-on of g2p-blender. Nothing is installed into the system.
#
#   scripts/check-packages.sh            # build, lintian, run (CI: .ci/run)
#   scripts/check-packages.sh --keep DIR # leave the packages and the root in DIR
#
# Needs dpkg-dev, debhelper, dh-python, help2man and lintian (scripts/install-deps.sh) and
# the build dependencies of debian/control. The compile flags are the test
# build's (debian/rules, G2P_DEB_TEST_BUILD_FLAGS), so ccache reuses the objects
# of .ci/run's build: about 4 minutes on 2 cores then (docs/testing.md).
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
keep=""
while [ $# -gt 0 ]; do
  case "$1" in
    --keep) keep="${2:?--keep needs a folder}"; shift 2 ;;
    -h|--help) sed -n '2,15p' "$0"; exit 0 ;;
    *) echo "check-packages.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
done

for tool in dpkg-buildpackage dh lintian dpkg-deb cmake pkg-config; do
  command -v "$tool" >/dev/null || { echo "check-packages.sh: $tool is missing (scripts/install-deps.sh installs it)" >&2; exit 1; }
done

if [ -n "$keep" ]; then
  mkdir -p "$keep"
  work="$(cd "$keep" && pwd)"
else
  work="$(mktemp -d "${TMPDIR:-/tmp}/g2p-packages.XXXXXX")"
  trap 'rm -rf "$work"' EXIT
fi
version="$(dpkg-parsechangelog -l "$here/debian/changelog" -S Version)"
src="$work/libg2p-$version"
root="$work/root"
rm -rf "$src" "$root" "$work"/*.deb "$work"/*.changes "$work"/*.buildinfo "$work"/run "$work"/run-network \
  "$work"/consumer "$work"/consumer-pc "$work"/*.log
mkdir -p "$src" "$root"
step() { echo "== check-packages: $*"; }

# The source as git sees it (committed and new files, not ignored ones) and the
# summary viewer's npm packages, which install-deps.sh put beside it.
step "copying the source tree to $src"
(cd "$here" && { git ls-files -z --cached --others --exclude-standard;
                 [ -d libg2p/web/node_modules ] && find libg2p/web/node_modules -type f -print0; } |
   tar --null -T - -cf -) | tar -C "$src" -xf -

step "dpkg-buildpackage -b -us -uc"
start=$(date +%s)
# debhelper points HOME elsewhere while it builds: ccache keeps its own folder.
ccache_dir="${CCACHE_DIR:-}"
if [ -z "$ccache_dir" ] && command -v ccache >/dev/null; then ccache_dir="$(ccache --get-config cache_dir)"; fi
(cd "$src" && CCACHE_DIR="$ccache_dir" DEB_BUILD_OPTIONS="parallel=$(nproc) nocheck noautodbgsym" G2P_DEB_TEST_BUILD_FLAGS=1 \
   dpkg-buildpackage -b -us -uc) > "$work/build.log" 2>&1 || {
  tail -60 "$work/build.log"; echo "check-packages.sh: dpkg-buildpackage failed (log: $work/build.log)" >&2; exit 1; }
step "built in $(( $(date +%s) - start )) s: $(cd "$work" && ls -- *.deb | tr '\n' ' ')"

expected=(libg2p0 libg2p-cgal0 libg2p-data libg2p-dev g2p python3-g2p g2p-blender)
for p in "${expected[@]}"; do
  ls "$work/${p}_${version}_"*.deb >/dev/null 2>&1 || { echo "check-packages.sh: no $p package was built" >&2; exit 1; }
done

step "lintian (errors fail the check)"
lintian --fail-on error --tag-display-limit 0 "$work"/libg2p_"${version}"_*.changes | tee "$work/lintian.log"

step "unpacking into $root"
for p in "${expected[@]}"; do dpkg-deb -x "$work/${p}_${version}_"*.deb "$root"; done
multiarch="$(dpkg-architecture -qDEB_HOST_MULTIARCH)"
libdir="$root/usr/lib/$multiarch"
[ -e "$libdir/libg2p.so.0" ] && [ -e "$libdir/libg2p_cgal.so.0" ] || { echo "check-packages.sh: the shared libraries are missing in $libdir" >&2; exit 1; }

# Nothing installed names the folder it was built in.
if grep -rl --binary-files=binary -F "$src" "$root" >/dev/null; then
  echo "check-packages.sh: installed files name the build folder $src:" >&2
  grep -rl --binary-files=binary -F "$src" "$root" >&2
  exit 1
fi

fail() { echo "check-packages.sh: $*" >&2; exit 1; }
hammer="$here/examples/data/hammer.obj"
export LD_LIBRARY_PATH="$libdir"

step "the consumer project against libg2p-dev (find_package and pkg-config)"
cmake -S "$here/tests/package/consumer" -B "$work/consumer" -DCMAKE_PREFIX_PATH="$root/usr" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$work/consumer" >/dev/null
out="$("$work/consumer/consumer" "$hammer")"
echo "$out"
[[ "$out" == *"faces 104"* && "$out" == *"material steel_head"* ]] || fail "the consumer printed unexpected output"
flags="$(PKG_CONFIG_PATH="$libdir/pkgconfig" pkg-config --cflags --libs g2p)"
# shellcheck disable=SC2086
c++ -std=c++17 "$here/tests/package/consumer/main.cpp" $flags -o "$work/consumer-pc"
"$work/consumer-pc" "$hammer" | grep -q "faces 104" || fail "the pkg-config build printed unexpected output"

step "g2p run from the g2p package, models from libg2p-data"
"$root/usr/bin/g2p" run "$hammer" -o "$work/run" --format mjcf,urdf -q | tee "$work/run.log"
grep -q "2 parts" "$work/run.log" || fail "g2p run printed no '2 parts'"
[ -s "$work/run/hammer.xml" ] && [ -s "$work/run/hammer.urdf" ] || fail "g2p run wrote no hammer.xml or hammer.urdf"
# The network alone (names=off): it fails unless libg2p-data's models are found beside the library.
G2P_MODEL_DIR="" "$root/usr/bin/g2p" run "$hammer" -o "$work/run-network" --segmenter learned --set names=off \
  --format mjcf -q > "$work/run-network.log" 2>&1 || { cat "$work/run-network.log"; fail "the installed g2p did not find the shipped network"; }
grep -E "^  segment +learned" "$work/run-network.log"
man -l "$root/usr/share/man/man1/g2p.1.gz" 2>/dev/null | grep -q "g2p run MODEL" || fail "the g2p(1) manual page is missing or empty"

step "import g2p from python3-g2p"
export PYTHONPATH="$root/usr/lib/python3/dist-packages"
/usr/bin/python3 - "$hammer" "$root" <<'EOF'
import sys
import g2p
assert g2p.__file__.startswith(sys.argv[2]), g2p.__file__
model = g2p.load_model(sys.argv[1])
assert model.material_names == ["oak_handle", "steel_head"], model.material_names
print("import g2p:", g2p.__version__, "from", g2p.__file__, "cgal:", g2p.with_cgal)
EOF

step "Blender enables the add-on from g2p-blender"
if command -v blender >/dev/null; then
  # The installed add-on folder as the user's scripts; PYTHONPATH reaches Blender's Python with
  # --python-use-system-env, as /usr/lib/python3/dist-packages does once the packages are installed.
  BLENDER_USER_SCRIPTS="$root/usr/share/blender/scripts" blender -b --factory-startup --python-use-system-env \
    --python-exit-code 1 --python-expr "
import addon_utils, bpy
mod = addon_utils.enable('g2p_blender', default_set=True)
assert mod is not None and mod.__file__.startswith('$root'), mod
import g2p
assert g2p.__file__.startswith('$root'), g2p.__file__
assert hasattr(bpy.types.Scene, 'g2p') and hasattr(bpy.ops.g2p, 'make_parts'), 'the add-on registered nothing'
print('Blender add-on:', mod.__file__, 'with', g2p.__file__)
" > "$work/blender.log" 2>&1 || { cat "$work/blender.log"; fail "Blender could not enable the installed add-on"; }
  grep "Blender add-on:" "$work/blender.log"
else
  step "Blender is not installed: the add-on was not tried (skipped)"
fi

step "all packages built, lintian clean of errors, installed files work"

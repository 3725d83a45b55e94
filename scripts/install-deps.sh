#!/usr/bin/env bash
# Installs every Debian 12 package that libg2p's build, tests, examples and
# bindings need. Idempotent and non-interactive; run as root or with sudo.
#
#   scripts/install-deps.sh            # build + tests + examples (default)
#   scripts/install-deps.sh --minimal  # only what libg2p itself links (all stages), no test/validation tools
set -euo pipefail

minimal=0
for arg in "$@"; do
  case "$arg" in
    --minimal) minimal=1 ;;
    -h|--help) sed -n '2,7p' "$0"; exit 0 ;;
    *) echo "install-deps.sh: unknown option '$arg'" >&2; exit 2 ;;
  esac
done

# Packages the library itself links (public: Eigen; private: the rest).
core=(
  build-essential cmake pkg-config ccache git
  libeigen3-dev libassimp-dev libembree-dev libtbb-dev
  libopencv-dev libpng-dev libjpeg-dev libwebp-dev libtiff-dev
  libdraco-dev libmeshoptimizer-dev
  libcgal-dev libgmp-dev libmpfr-dev
  nlohmann-json3-dev libcli11-dev libcurl4-openssl-dev
  liburdfdom-dev libqhull-dev
)
# Tests, validation with real consumers, benchmarks, bindings; WordNet for the
# object table's check (scripts/objects/build_objects.py --check); Chromium for
# the summary.html browser tests (headless); DART 6.12 with its URDF and SDF
# readers and ODE's collision detector, the second engine the URDF and SDF are
# dropped in (tests/export/dart_test.cpp; about 200 MB, most of it Boost);
# Blender 3.4 for the add-on's headless test (tests/blender; 363 MB installed);
# debhelper, dh-python, help2man and lintian build and check the Debian packages
# (debian/, scripts/check-packages.sh).
extra=(
  libgtest-dev libgmock-dev libbenchmark-dev
  assimp-testmodels
  wordnet-base
  libmujoco-dev libgl-dev libopengl-dev libbullet-extras-dev
  liburdfdom-tools libsdformat-dev libcpp-httplib-dev
  libdart-dev libdart-utils-dev libdart-utils-urdf-dev libdart-collision-ode-dev
  pybind11-dev python3-dev python3-numpy python3-onnx
  python3-pandas python3-dask python3-distributed
  clang libclang-rt-14-dev
  chromium
  blender
  debhelper dh-python help2man lintian
)

pkgs=("${core[@]}")
[ "$minimal" = 1 ] || pkgs+=("${extra[@]}")
# Node.js runs the Khronos glTF validator in the tests; a machine that already
# has node and npm (from any source) keeps them.
if [ "$minimal" = 0 ] && ! { command -v node && command -v npm; } >/dev/null; then pkgs+=(nodejs npm); fi

# The npm packages, from the npm registry, each folder pinned by its package-lock.json:
# libg2p/web (three.js and esbuild: summary.html's 3D view, bundled into libg2p
# at build time; without them the page has no 3D view) and tests/validators
# (the Khronos glTF validator; playwright-core, which drives Chromium in the
# summary.html browser tests) and tests/compressors (glTF Transform and
# gltfpack, which make the compressed variants the import tests read).
install_npm() {
  [ "$minimal" = 1 ] && return 0
  local root dir
  root="$(cd "$(dirname "$0")/.." && pwd)"
  for dir in "$root/libg2p/web" "$root/tests/validators" "$root/tests/compressors"; do
    if node -e 'const d = process.argv[1], fs = require("fs");
                process.exit(Object.keys(require(d + "/package.json").dependencies)
                  .every((p) => fs.existsSync(d + "/node_modules/" + p + "/package.json")) ? 0 : 1)' "$dir"; then
      echo "install-deps: npm packages already installed in ${dir#"$root"/}"
      continue
    fi
    echo "install-deps: npm ci in ${dir#"$root"/}"
    npm ci --prefix "$dir" --no-audit --no-fund --loglevel=error
  done
}

# Skip apt entirely when everything is already there (fast re-runs, offline CI).
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ "${#missing[@]}" -eq 0 ]; then
  echo "install-deps: all ${#pkgs[@]} packages already installed"
  install_npm
  exit 0
fi

run_root() { "$@"; }
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install-deps: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
  run_root() { sudo DEBIAN_FRONTEND=noninteractive "$@"; }
fi
echo "install-deps: installing ${#missing[@]} packages: ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
run_root apt-get update -q
run_root apt-get install -y -q --no-install-recommends "${missing[@]}"
install_npm

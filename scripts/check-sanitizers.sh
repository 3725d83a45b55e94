#!/usr/bin/env bash
# The sanitizer and fuzzing job (docs/testing.md), run by .ci/run after the
# main test suite. In build-asan/ it builds libg2p, its tools, tests and fuzz
# targets with Clang, AddressSanitizer (with LeakSanitizer) and
# UndefinedBehaviorSanitizer, runs the test suite there, then runs every fuzz
# target for a bounded time from a seed corpus made of ../shared/assets and
# Debian's assimp-testmodels. Any report, crash, leak or hang fails the job
# (assimp parses in a child process, so a crash inside it is an import error,
# not a crash of the fuzzer; fuzz/import_fuzzer.cpp fails on one in libg2p's
# own code there); a fuzzer's crashing input is kept in build-asan/fuzz/artifacts/ (commit it
# to fuzz/corpus/TARGET/ with the fix, so the suite replays it from then on).
#
#   scripts/check-sanitizers.sh [--fuzz-seconds N] [--no-tests] [--no-fuzz] [--build DIR]
#   (--fuzz-seconds 0 prepares each fuzzer's seeds without running it)
set -euo pipefail
cd "$(dirname "$0")/.."

fuzz_seconds=60
run_tests=1
run_fuzz=1
build=build-asan
while [ $# -gt 0 ]; do
  case "$1" in
    --fuzz-seconds) fuzz_seconds="$2"; shift ;;
    --no-tests) run_tests=0 ;;
    --no-fuzz) run_fuzz=0 ;;
    --build) build="$2"; shift ;;
    -h|--help) sed -n '2,12p' "$0"; exit 0 ;;
    *) echo "check-sanitizers.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
  shift
done
case "$fuzz_seconds" in ''|*[!0-9]*) echo "check-sanitizers.sh: --fuzz-seconds needs a whole number, got '$fuzz_seconds'" >&2; exit 2 ;; esac
command -v clang++ >/dev/null || { echo "check-sanitizers.sh: clang++ not found (scripts/install-deps.sh installs clang)" >&2; exit 1; }

t0=$(date +%s)
stamp() { echo "check-sanitizers: $1 at $(( $(date +%s) - t0 )) s"; }

# ccache hits across checkouts in other folders (CI's clean clone): paths
# relative to the checkout, and the build folder left out of the hash.
export CCACHE_BASEDIR="$PWD" CCACHE_NOHASHDIR=1

# -O2: Eigen needs inlining (at -O1 the suite ran 20 to 50 times slower than
# the release build); line tables give readable reports.
cmake -S . -B "$build" -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -gline-tables-only" \
  -DG2P_SANITIZE=address,undefined -DG2P_BUILD_FUZZERS=ON -DG2P_BUILD_TESTS=ON \
  -DG2P_BUILD_PYTHON=OFF -DG2P_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build "$build" -j"$(nproc)"
stamp "built"

export ASAN_OPTIONS="detect_leaks=1:strict_string_checks=1:check_initialization_order=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export LSAN_OPTIONS="suppressions=$PWD/scripts/sanitizers/lsan.supp:print_suppressions=0"

if [ "$run_tests" = 1 ]; then
  # package.*: builds a consumer with the system compiler against the installed
  # library, which cannot link an ASan build. TooLittleMemory...: runs g2p under
  # `ulimit -v`, where ASan cannot reserve its shadow memory; TheMemoryLimit...:
  # runs g2p under a 0.5 GiB RLIMIT_DATA, which ASan's own mappings exceed. The
  # main job runs all three.
  # scripts/sanitizers/release-only.txt: the slowest tests, whose code runs
  # here in smaller tests; the main job runs them.
  release_only=$(sed -e 's/#.*//' -e 's/[[:space:]]*$//' -e '/^$/d' scripts/sanitizers/release-only.txt | paste -sd'|')
  ctest --test-dir "$build" --output-on-failure -j2 \
    -E "^package\\.|^ToolRun\\.TooLittleMemoryIsACleanErrorNotACrash\$|^batch\\.BatchRun\\.TheMemoryLimitReachesEveryWorker\$|$release_only"
  stamp "test suite passed under ASan+UBSan"
fi

if [ "$run_fuzz" = 1 ]; then
  seeds="$build/fuzz/seeds"
  "$build/bin/g2p_fuzz_seeds" ../shared/assets "$seeds" >/dev/null
  fuzz_one() {  # TARGET KIND
    local target=$1 kind=$2 dir="$build/fuzz/run/$1"
    rm -rf "$dir" && mkdir -p "$dir/corpus" "$dir/seeds" "$build/fuzz/artifacts"
    cp "$seeds/$kind"/* fuzz/corpus/"$target"/* "$dir/seeds/"
    local assimp_dir=""
    case "$kind" in glb|gltf) assimp_dir=glTF2 ;; obj) assimp_dir=OBJ ;; ply) assimp_dir=PLY ;; stl) assimp_dir=STL ;; esac
    if [ -n "$assimp_dir" ]; then
      find "/usr/share/assimp/models/$assimp_dir" -type f -iname "*.$kind" -size -256k |
        while read -r f; do cp "$f" "$dir/seeds/$(echo "$f" | md5sum | cut -c1-12).$kind"; done
    fi
    if [ "$fuzz_seconds" = 0 ]; then echo "fuzz $target: seeds in $dir/seeds (not run: --fuzz-seconds 0)"; return 0; fi
    if "$build/bin/g2p_fuzz_$target" -max_total_time="$fuzz_seconds" -timeout=30 -rss_limit_mb=3072 \
        -max_len=262144 -print_final_stats=1 -artifact_prefix="$build/fuzz/artifacts/$target-" \
        "$dir/corpus" "$dir/seeds" >"$dir/log.txt" 2>&1; then
      echo "fuzz $target: $(grep -m1 -o 'stat::number_of_executed_units: *[0-9]*' "$dir/log.txt" | grep -o '[0-9]*$') runs in ${fuzz_seconds} s, seeds $(ls "$dir/seeds" | wc -l), corpus $(ls "$dir/corpus" | wc -l), no crash"
    else
      echo "fuzz $target: FAILED; the report ends:" >&2
      tail -n 60 "$dir/log.txt" >&2
      return 1
    fi
  }
  export -f fuzz_one
  export build seeds fuzz_seconds
  # Two at a time (two cores); every target runs even when one fails.
  printf '%s\n' "import_glb glb" "import_gltf gltf" "import_obj obj" "import_ply ply" "import_stl stl" \
                "faces_csv faces_csv" "labels_json labels_json" "overrides_json overrides_json" \
                "objects_json objects_json" |
    xargs -P 2 -L 1 bash -c 'fuzz_one "$0" "$1"'
  stamp "fuzzing passed"
fi
stamp "done"

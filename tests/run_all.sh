#!/usr/bin/env bash
# The README's second command (and the whole of .ci/run): install what is missing, build,
# and run every test with CTest. Tests that need ../shared/datasets skip with a message when
# it is absent. Then the same suite under AddressSanitizer + UndefinedBehaviorSanitizer
# (build_asan), and each libFuzzer target of tests/fuzz/ for a bounded time on a copy of its
# committed corpus when clang's libFuzzer is available (docs/robustness.md).
# OPENABLE_SANITIZE_STEP=0 skips the sanitizer step, OPENABLE_FUZZ_SECONDS sets the time of
# each fuzzer (60 s; 0 skips them). Each step ends with its wall time ("== ... done in N s"),
# so that a slow CI run shows where its time went.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
jobs=${OPENABLE_JOBS:-$(nproc)}
step_start=$SECONDS
done_step() { echo "== $1 done in $((SECONDS - step_start)) s"; step_start=$SECONDS; }
bash examples/setup.sh --all
done_step "Set-up and build (examples/setup.sh --all)"
(cd build && ctest --output-on-failure -j"$jobs" --timeout 1200)
done_step "Test suite"

[ "${OPENABLE_SANITIZE_STEP:-1}" = 0 ] && exit 0

# Sanitized suite: any ASan or UBSan report fails the test that triggered it. The
# suppressions (tests/sanitizers/) cover third-party code only; each one says why.
# fast_unwind_on_malloc=0: full allocation stacks through the (frame-pointer-less) Debian
# libraries, so that the LSan suppressions, which name third-party frames, match.
# Leak checking is on in the fuzzers and off for the suite, whose GCC LeakSanitizer can crash in
# its own tracer at the exit of a test that passed (docs/robustness.md, "Leak checking").
export ASAN_OPTIONS="detect_leaks=1:fast_unwind_on_malloc=0:strict_string_checks=1:detect_stack_use_after_return=1:check_initialization_order=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:suppressions=$root/tests/sanitizers/ubsan.supp"
export LSAN_OPTIONS="suppressions=$root/tests/sanitizers/lsan.supp:print_suppressions=0"
echo "== Sanitized suite (ASan + UBSan) in build_asan"
# -O1 -g1, unity builds for Ninja: docs/robustness.md, "Running them".
asan_settings=()
[ -f build_asan/CMakeCache.txt ] || asan_settings+=(-G Ninja -DOPENABLE_UNITY_BUILD=ON)
cmake -S . -B build_asan "${asan_settings[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
      -DOPENABLE_SANITIZE=address \
      -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" \
      -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" \
      -DOPENABLE_BUILD_BENCHMARKS=OFF
cmake --build build_asan -j"$jobs"
done_step "Sanitized build"
# Eleven slow real-data tests are left out of the sanitized suite; each runs in the normal suite
# above and the code it runs is sanitized in smaller tests (docs/robustness.md lists which).
# The install.* tests run no compiled code of the project.
(cd build_asan && ASAN_OPTIONS="${ASAN_OPTIONS/detect_leaks=1/detect_leaks=0}" \
   ctest --output-on-failure -j"$jobs" --timeout 2400 \
         -E '^(install\..*|TestOpenABLE\.DescriptorCacheResumeIsBitIdentical|Sweep\.FiguresEqualTheSingleRunsAndAreRanked|SoDsoReport\.SignedChangesAReadingAndAHintForTheConvention|Auto\.TheRunOfTheChoiceIsThePlainRunOfItsSettingsByteForByte|EvaluationOnDatasets\.NordlandWinterAgainstSummer|SnapsChain\.KittiMonocularOdometryLoopsFromOpenableAndCorrection|Auto\.NightLikeGardensPointIsWithinTheBestOfTheSweep|MonoOdometry\.KittiFrames0To199StayCloseToTheGroundTruth|Verification\.OnlineDetectorGivesTheBatchRunsLoops|Library\.BatchPathGivesTestOpenablesMatrixAndFigures|Kitti/SoDso\.CorrectsWithGroundTruthPairsAndWritesWhatItReports/seq00)( |$)')
done_step "Sanitized suite"

fuzz_seconds=${OPENABLE_FUZZ_SECONDS:-60}
[ "$fuzz_seconds" = 0 ] && exit 0
probe=$(mktemp -d)
trap 'rm -rf "$probe"' EXIT
echo 'extern "C" int LLVMFuzzerTestOneInput(const char*, unsigned long) { return 0; }' \
  > "$probe/probe.cc"
if ! command -v clang++ > /dev/null ||
   ! clang++ -fsanitize=fuzzer "$probe/probe.cc" -o "$probe/probe" 2> /dev/null; then
  echo "== Fuzzers skipped: clang++ with libFuzzer is not available (examples/setup.sh --all installs it)"
  exit 0
fi
fuzz_settings=()
[ -f build_fuzz/CMakeCache.txt ] || fuzz_settings+=(-G Ninja -DOPENABLE_UNITY_BUILD=ON)
CXX=clang++ cmake -S . -B build_fuzz "${fuzz_settings[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
      -DOPENABLE_BUILD_FUZZERS=ON -DOPENABLE_BUILD_TESTS=OFF -DOPENABLE_BUILD_BENCHMARKS=OFF
cmake --build build_fuzz -j"$jobs" --target fuzzers
# The fuzzers the build made (the bag fuzzer only with the rosbag module), each <name>_fuzzer
# with its corpus tests/fuzz/corpus/<name>/.
mapfile -t fuzzers < build_fuzz/tests/fuzz/fuzzers.txt
echo "== Fuzzers (${fuzz_seconds} s each, two at a time) in build_fuzz: ${fuzzers[*]}"
# LeakSanitizer's tracer can crash at the exit of a fuzzer run whose inputs all passed, with no
# report of ASan, UBSan or libFuzzer (docs/robustness.md): such a run is made once more, so that
# the leak check still runs; a real finding fails as before.
lsan_tool_fault() {
  grep -aq 'LeakSanitizer has encountered a fatal error' "$1" &&
    ! grep -aq -e 'ERROR: AddressSanitizer' -e 'ERROR: libFuzzer' -e 'runtime error:' \
      -e 'ERROR: LeakSanitizer: detected' "$1"
}
run_fuzzer() {
  local name=$1 status=0 attempt
  cp -r "tests/fuzz/corpus/$name" "$probe/$name"  # new inputs go to the copy, never the committed corpus
  for attempt in 1 2; do
    status=0
    rm -f "$probe/${name}-"*
    "build_fuzz/tests/fuzz/${name}_fuzzer" -max_total_time="$fuzz_seconds" -max_len=65536 \
      -timeout=30 -rss_limit_mb=3072 -print_final_stats=1 -artifact_prefix="$probe/${name}-" \
      "$probe/$name" > "$probe/${name}.log" 2>&1 || status=$?
    [ "$status" -ne 0 ] && lsan_tool_fault "$probe/${name}.log" || break
    cp "$probe/${name}.log" "$probe/${name}.first.log"
    echo "== ${name}_fuzzer: LeakSanitizer's tracer failed at exit (a fault of the tool); run again"
  done
  echo "$status" > "$probe/${name}.status"
}
# Two side by side (one core each): a new one starts when one ends. Then each log is read in turn.
running=0
for name in "${fuzzers[@]}"; do
  if [ "$running" -ge 2 ]; then
    wait -n
    running=$((running - 1))
  fi
  run_fuzzer "$name" &
  running=$((running + 1))
done
wait
for name in "${fuzzers[@]}"; do
  echo "-- ${name}_fuzzer"
  status=$(cat "$probe/${name}.status")
  # The decoders' own complaints (libpng, libjpeg, OpenImageIO, GDAL's two-line NITF error,
  # OpenCV's imdecode and imread) and progress lines are noise.
  grep -v -e '^#[0-9]' -e '^libpng' -e 'JPEG' -e '^INFO: ' -e '^imdecode_' -e '^imread_' \
    -e '^ERROR [0-9]*: ' -e '^or empty\.$' -e '^$' "$probe/${name}.log" | tail -n 40 || true
  if [ "$status" -ne 0 ] || ls "$probe/${name}-"* > /dev/null 2>&1; then
    mkdir -p build_fuzz/artifacts
    cp "$probe/${name}.log" "$probe/${name}-"* build_fuzz/artifacts/ 2> /dev/null || true
    echo "${name}_fuzzer failed (exit $status); log and failing input in build_fuzz/artifacts" \
         "(reproduce: build_fuzz/tests/fuzz/${name}_fuzzer FILE)"
    exit 1
  fi
done
done_step "Fuzzers"

#!/usr/bin/env bash
# Runs each libFuzzer target of the fuzz preset for a bounded time and reports executions and
# coverage; fails on the first crash, leak, timeout or out-of-memory (libFuzzer writes the input
# as crash-*/leak-*/timeout-*/oom-* in the working folder: copy it into tests/fuzz/corpus/<target>
# as a regression case once fixed).
#   tests/fuzz/run_fuzzers.sh SECONDS [TARGET...]     (default: every target)
#   FUZZ_SEED=1 tests/fuzz/run_fuzzers.sh 30           (CI: a fixed seed and run count, the same inputs every run)
# Two targets run at once on a machine with two or more cores. Corpora grow in build/fuzz/corpus.
set -euo pipefail
cd "$(dirname "$0")/../.."
seconds=${1:?usage: run_fuzzers.sh SECONDS [TARGET...]}
shift
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(brs vox scene octobvh_edits grid_edits broadphase)
bin=build/fuzz/bin
shared=../shared/data

run_one() {
  local t=$1 work=build/fuzz/corpus/$1 log=build/fuzz/logs/$1.log
  mkdir -p "$work" build/fuzz/logs build/fuzz/findings/"$t"
  local seeds=(tests/fuzz/corpus/"$t")
  case $t in
    scene) seeds+=(profiles/scenes) ;;
    brs) [ -d "$shared" ] && seeds+=(build/fuzz/seeds/brs) ;;
    vox) [ -d "$shared" ] && seeds+=(build/fuzz/seeds/vox) ;;
  esac
  local opts=(-max_total_time="$seconds" -timeout=20 -rss_limit_mb=2048 -print_final_stats=1
              -artifact_prefix=build/fuzz/findings/"$t"/)
  [ -f tests/fuzz/"$t".dict ] && opts+=(-dict=tests/fuzz/"$t".dict)
  # CI: a fixed seed and a fixed number of runs per target (each count about 60 s here, scaled
  # to the seconds given), so every CI run tries the same inputs: a pass here is a pass there (a
  # slower machine stops at the time cap first, trying a prefix of the same inputs). Findings
  # come from the long random runs.
  if [ -n "${FUZZ_SEED:-}" ]; then
    opts+=(-seed="$FUZZ_SEED")
    local per_minute=0  # a target without a count here runs to the time cap
    case $t in
      brs) per_minute=30000 ;;
      vox) per_minute=800000 ;;
      scene) per_minute=40000 ;;
      octobvh_edits) per_minute=12000 ;;
      grid_edits) per_minute=7000 ;;
      broadphase) per_minute=10000 ;;
    esac
    [ "$per_minute" -gt 0 ] && opts+=(-runs=$(( per_minute * seconds / 60 )))
  fi
  # the real content files are large: only their first 64 KiB seed the byte targets
  case $t in brs|vox) opts+=(-max_len=65536) ;; esac
  if "$bin/fuzz_$t" "${opts[@]}" "$work" "${seeds[@]}" > "$log" 2>&1; then
    local runs cov
    runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo '?')
    cov=$(grep -o 'cov: [0-9]* ft: [0-9]*' "$log" | tail -1 || echo 'cov: ?')
    echo "fuzz_$t: clean, $runs executions (at most ${seconds} s), $cov, corpus $(ls "$work" | wc -l) inputs"
  else
    echo "fuzz_$t: FAILED (log $log, input in build/fuzz/findings/$t/)"
    grep -m5 -E 'ERROR|FUZZ_CHECK|terminate|what\(\)' "$log" || tail -20 "$log"
    return 1
  fi
}

# The real content files as seeds (copied: libFuzzer's seed folders must hold only inputs).
if [ -d "$shared" ]; then
  mkdir -p build/fuzz/seeds/brs build/fuzz/seeds/vox
  cp -f "$shared"/*.brs build/fuzz/seeds/brs/ 2>/dev/null || true
  cp -f "$shared"/*.vox build/fuzz/seeds/vox/ 2>/dev/null || true
fi

parallel=$(( $(nproc) >= 2 ? 2 : 1 ))
status=0
pids=()
for t in "${targets[@]}"; do
  run_one "$t" &
  pids+=($!)
  if [ ${#pids[@]} -ge "$parallel" ]; then
    wait "${pids[0]}" || status=1
    pids=("${pids[@]:1}")
  fi
done
for p in "${pids[@]}"; do wait "$p" || status=1; done
exit $status

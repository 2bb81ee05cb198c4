#!/usr/bin/env bash
# Run every fuzz target for $1 seconds (default 600), one after another on
# one core; each log ends with libFuzzer's execution count.
set -u
secs=${1:-600}
cd "$(dirname "$0")"
for t in scene_text curve_text knot_points recording_bytes; do
  mkdir -p corpus/$t
  cargo +nightly fuzz run -O $t corpus/$t -- -max_total_time=$secs -rss_limit_mb=2048 \
    -malloc_limit_mb=2048 -timeout=60 -max_len=65536 > logs_$t.txt 2>&1
  echo "$t exit $?: $(grep -E '^(Done|#[0-9]+ *DONE)' logs_$t.txt | tail -1)"
done

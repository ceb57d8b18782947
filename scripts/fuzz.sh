#!/usr/bin/env bash
# Runs one fuzz target of fuzz/ (obj, tris or rom; docs/FUZZING.md) for SECONDS:
#   scripts/fuzz.sh TARGET SECONDS [libFuzzer options…]
# Built with debug assertions and overflow checks (cargo fuzz -a) and AddressSanitizer, on the
# stable toolchain (RUSTC_BOOTSTRAP=1 lets it take cargo fuzz's nightly flags); installs
# cargo-fuzz if it is missing. The committed seeds (fuzz/corpus/TARGET) are read, never
# written: what the run learns goes to fuzz/work/TARGET, a crash to fuzz/artifacts/TARGET.
# Exit status: libFuzzer's (0 when the time ran out without a finding). A hang is an input
# running over 10 s; an absurd allocation one malloc over 512 MB or 2 GB resident.
set -euo pipefail

usage="usage: scripts/fuzz.sh obj|tris|rom SECONDS [libFuzzer options…]"
target=${1:?$usage}
seconds=${2:?$usage}
shift 2
case $target in obj | tris | rom) ;; *) echo "$usage" >&2; exit 2 ;; esac
[[ $seconds =~ ^[0-9]+$ ]] || { echo "$usage" >&2; exit 2; }

root=$(cd "$(dirname "$0")/.." && pwd)
command -v cargo-fuzz >/dev/null || cargo install cargo-fuzz --locked
work=$root/fuzz/work/$target
mkdir -p "$work/corpus" "$work/tmp" "$root/fuzz/artifacts/$target"
dict=()
[[ -f $root/fuzz/dict/$target.dict ]] && dict=(-dict="$root/fuzz/dict/$target.dict")

cd "$root/fuzz"
export RUSTC_BOOTSTRAP=1
# `rom` writes its inputs into a scratch folder under TMPDIR: kept inside fuzz/work, removed after.
status=0
TMPDIR=$work/tmp cargo fuzz run --debug-assertions "$target" "$work/corpus" "corpus/$target" -- \
    -max_total_time="$seconds" -timeout=10 -malloc_limit_mb=512 -rss_limit_mb=2048 \
    -print_final_stats=1 "${dict[@]}" "$@" || status=$?
rm -rf "$work/tmp"
exit "$status"

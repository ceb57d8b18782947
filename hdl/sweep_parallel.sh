#!/bin/bash
# The fxrt sweep without Slurm: runs the {{ shards }} shard commands of commands.txt with GNU
# parallel ({{ cpus }} threads each, JOBS shards at a time), then merges them.
set -euo pipefail
cd "$(dirname "$0")"
parallel --halt now,fail=1 -j "${JOBS:-1}" < commands.txt
{{ merge }}

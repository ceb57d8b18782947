#!/bin/bash
# Queues the fxrt sweep's {{ shards }} shards as a job array, then the merge after all of them.
set -euo pipefail
cd "$(dirname "$0")"
mkdir -p {{ out }}/slurm
jid=$(sbatch --parsable sweep.slurm)
sbatch --dependency=afterok:"${jid%%;*}" merge.slurm

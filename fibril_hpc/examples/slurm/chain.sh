#!/bin/bash
# Pre-submit N chained jobs of one campaign: job i+1 starts after job i ends, whatever its exit
# (afterany), and resumes the file. Safe even if a job is killed hard (no signal): every job
# resumes from the file; jobs that find nothing left to do finish in seconds.
#   slurm/chain.sh N GRID.yaml [sbatch options --] [fibril-campaign options]
#   e.g. slurm/chain.sh 5 campaigns/paper.yaml --ntasks=33 --time=12:00:00 --
set -eu
N=${1:?usage: slurm/chain.sh N GRID.yaml [sbatch options --] [fibril-campaign options]}
GRID=${2:?usage: slurm/chain.sh N GRID.yaml [sbatch options --] [fibril-campaign options]}
shift 2
SB=()
if printf '%s\n' "$@" | grep -qx -- '--'; then
  while [ "$1" != "--" ]; do SB+=("$1"); shift; done
  shift
fi
here=$(cd "$(dirname "$0")" && pwd)
dep=()
for i in $(seq 1 "$N"); do
  id=$(sbatch --parsable "${SB[@]}" "${dep[@]}" --export=ALL,FIBRIL_CHAIN_MAX=0 \
       "$here/campaign.sbatch" "$GRID" "$@")
  echo "submitted $id"
  dep=(--dependency=afterany:"${id%%;*}")
done

#!/bin/bash
# Rebuilds the calibrations of dustdem against the dynamic compression curves of Seizinger et
# al. (2012) at 2.5, 5 and 10 m/s (measured.py writes the data from the paper's Eqs. 13, 15
# and 17): 4000-monomer samples on seeds 1-3, a first screen on 2000. Add --cache-only to
# rebuild the reports from the committed run cache without simulating
# (tests/calibrate/paper_dynamic.rs does so). `make.sh n40000 [--slurm ...]` instead runs the
# search at the paper's 40 000 monomers with a screen on 8000 (README: some 2-3 CPU-hours at
# the least; not yet made).
set -euo pipefail
cd "$(dirname "$0")/../../.."
BIN=${DUSTDEM:-target/release/dustdem}
DIR=docs/calibration/paper_dynamic
if [ "${1:-}" = n40000 ]; then
    shift
    exec $BIN calibrate --measured "$DIR/measured.toml" --config "$DIR/config_n40000.toml" \
        --seeds 1,2,3 --screen-monomers 8000 --cache "$DIR/run_cache_n40000" \
        --out "$DIR/n40000" "$@"
fi
for sigma in "" _scatter_only; do
    $BIN calibrate --measured "$DIR/measured$sigma.toml" --config "$DIR/config.toml" \
        --seeds 1,2,3 --screen-monomers 2000 --threads 2 --cache "$DIR/run_cache" \
        --out "$DIR/n4000$sigma" "$@"
done

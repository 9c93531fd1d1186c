#!/bin/bash
# Rebuilds the four hidden-pair calibrations of this folder: synthetic data (3 RBD samples of
# 120 monomers per curve, omni + uni + sticking), calibrated on 3 other seeds with a first
# screen on 60 monomers. Add --cache-only to the calibrate line to rebuild the reports from the
# committed run cache without simulating (tests/hidden_pairs.rs does so).
set -euo pipefail
cd "$(dirname "$0")/../../.."
BIN=${DUSTDEM:-target/release/dustdem}
DIR=docs/calibration/hidden_pairs
k=0
for pair in "rolling_stiffness=4 normal_damping=2" \
    "surface_energy=0.75 twisting_stiffness=6" \
    "side_wall_strength=300 surface_energy=1.5" \
    "critical_rolling_length=4 normal_damping=0.5"; do
    k=$((k + 1))
    name=$(echo "$pair" | tr ' =' '_-')
    measured=$DIR/measured_$name.toml
    if [ ! -f "$measured" ]; then
        effects=""
        for e in $pair; do effects="$effects --effect $e"; done
        # shellcheck disable=SC2086
        $BIN synth --config configs/calibrate_quick.toml $effects --geometry omni,uni \
            --seeds "50$k,51$k,52$k" --noise-seed "50$k" --out "$measured" --threads 2
    fi
    $BIN calibrate --measured "$measured" --config configs/calibrate_quick.toml \
        --seeds 1,2,3 --screen-monomers 60 --threads 2 --cache "$DIR/run_cache" \
        --out "$DIR/$name" "$@"
done

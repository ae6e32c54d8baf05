#!/usr/bin/env bash
# Side by side, in one run: lodeval's FLIP and SSIM against NVIDIA's C++ FLIP (flip-evaluator,
# single-threaded and default) and scikit-image SSIM on the same 1024² pair.
# Needs: pip install flip-evaluator==1.7 scikit-image pillow numpy
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
REF=reference/oracles/flip/bunny_1024_ref.png
TEST=reference/oracles/flip/bunny_1024_test.png
echo "== lodeval (all cores)"; target/release/lodeval bench metrics "$REF" "$TEST" --runs 5
echo "== lodeval (1 thread)"; target/release/lodeval bench metrics "$REF" "$TEST" --runs 5 --threads 1
echo "== references, OMP_NUM_THREADS=1"; OMP_NUM_THREADS=1 python3 benches/metrics_vs_reference.py "$REF" "$TEST" 5
echo "== references, default threads"; python3 benches/metrics_vs_reference.py "$REF" "$TEST" 5

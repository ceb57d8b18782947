#!/usr/bin/env bash
# Runs the golden model's tests (the library's, tests/precision.rs and tests/exact.rs) once with
# each code path forced through $FXRT_GOLDEN_PATH (render::fast::GoldenPath): reference,
# scalar, avx2, avx512. A path this CPU cannot run falls back to the fastest one it can, which the
# test output says (the unit test `primary_rows_give_the_hardware_traversal_answer` checks every
# available path on every pixel in each run anyway). Minutes per path.
set -euo pipefail
cd "$(dirname "$0")/.."
for path in reference scalar avx2 avx512; do
    echo "== FXRT_GOLDEN_PATH=$path" >&2
    FXRT_GOLDEN_PATH=$path cargo test --release --quiet --lib -- render:: model:: verify::frame
    FXRT_GOLDEN_PATH=$path cargo test --release --quiet --test precision --test exact
done
echo "every golden-model test passed with each path forced" >&2

//! Fuzz target `rom`: the body is `fxrt::fuzzing::rom` (docs/FUZZING.md).
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::sync::LazyLock;

static DIR: LazyLock<std::path::PathBuf> = LazyLock::new(fxrt::fuzzing::scratch_dir);

fuzz_target!(|data: &[u8]| {
    // An error is a clean refusal (exit code 2 in the command line); only a panic, an abort,
    // a hang or a runaway allocation is a finding.
    let _ = fxrt::fuzzing::run("rom", data, &DIR);
});

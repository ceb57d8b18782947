//! Fuzz target `obj`: the body is `fxrt::fuzzing::obj` (docs/FUZZING.md).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    // An error is a clean refusal (exit code 2 in the command line); only a panic, an abort,
    // a hang or a runaway allocation is a finding.
    let _ = fxrt::fuzzing::obj(data);
});

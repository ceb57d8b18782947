//! Checking the generated hardware against the golden model: whole frames through the core
//! (`frame`, `fxrt sim`) with its feeds (`feed`) and disturbances (`disturb`), the
//! intersection pipeline against test vectors (`vectors`, `check`, `fxrt test`), the
//! self-checking testbenches (`testbench`) and the external simulators that run them
//! (`simulators`), and the differential campaign (`exact`, `fxrt bench exact`).

pub mod check;
pub mod disturb;
pub mod exact;
pub mod feed;
pub mod frame;
pub mod frame_memory;
pub mod memory;
pub mod memory_hdl;
pub mod memory_tests;
pub mod simulators;
pub mod testbench;
pub mod vectors;

#[cfg(test)]
mod core_tests;

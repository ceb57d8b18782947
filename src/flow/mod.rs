//! Running the generated HDL: testbenches and the external simulators.

pub mod simulators;
pub mod testbench;

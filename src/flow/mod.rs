//! Running the generated HDL: testbenches and the external simulators.

pub mod axis;
pub mod board;
pub mod check;
pub mod disturb;
pub mod embree;
pub mod ecp5;
pub mod ecp5_bram;
pub mod ecp5_carry;
pub mod ecp5_dsp;
pub mod feed;
pub mod frame;
pub mod generate;
pub mod simulators;
pub mod sweep;
pub mod synth;
pub mod testbench;
pub mod vectors;

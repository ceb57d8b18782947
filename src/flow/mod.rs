//! Running the generated HDL: testbenches and the external simulators.

pub mod axis_host;
pub mod board;
pub mod check;
pub mod disturb;
pub mod ecp5;
pub mod ecp5_bram;
pub mod ecp5_carry;
pub mod ecp5_dsp;
pub mod embree;
pub mod exact;
pub mod feed;
pub mod frame;
pub mod generate;
pub mod simulators;
pub mod sweep;
pub mod synth;
pub mod testbench;
pub mod vectors;

/// Where scripts/install-deps.sh puts the Python tools: `./.venv/bin`, then the source tree's.
pub fn venv_bins() -> [std::path::PathBuf; 2] {
    [std::path::PathBuf::from(".venv/bin"), std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(".venv/bin")]
}

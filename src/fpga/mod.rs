//! The generated HDL on FPGA tools: the ECP5 flow (`ecp5`, yosys and nextpnr-ecp5: a measured
//! clock frequency, with the cores' block RAMs, carry chains and multipliers as ECP5
//! primitives) and the Xilinx area estimates (`xilinx`, yosys `synth_xilinx`).

pub mod device;
pub mod ecp5;
pub mod xilinx;
pub mod xilinx_bram;

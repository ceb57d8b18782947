//! The runtime-width RTL description: one netlist drives the cycle-accurate simulator and the
//! VHDL and Verilog printers, so the three cannot disagree on a width or a sign.

pub mod batch;
pub mod build;
pub mod bus;
pub mod emit;
pub mod flatten;
pub mod fsm;
pub mod names;
pub mod netlist;
pub mod pipeline;
pub mod random;
pub mod sim;
mod sim_ops;
pub mod width;

pub use netlist::{Module, Sig};
pub use width::{BinOp, Ty, UnOp};

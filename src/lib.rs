//! fxrt: a generator of fixed-point ray tracing hardware (after Hanika 2007), and the models
//! that prove it correct. The modules follow the data path: scene → model → render; the cores
//! describe the hardware, which `verify` checks against the models, `fpga` synthesises,
//! `generate` writes out, `board` puts on a board and `sweep` measures over parameters
//! (tests/architecture.rs holds their order).

pub mod bits;
pub mod board;
pub mod cli;
pub mod cores;
pub mod error;
pub mod fpga;
pub mod fuzzing;
pub mod generate;
pub mod io;
pub mod model;
pub mod params;
pub mod render;
pub mod rng;
pub mod rtl;
pub mod scene;
pub mod sweep;
pub mod verify;

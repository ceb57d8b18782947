//! fxrt: a generator of fixed-point ray tracing hardware (after Hanika 2007), and the models
//! that prove it correct. The modules follow the data path: scene → model → render.

pub mod bits;
pub mod cli;
pub mod cores;
pub mod error;
pub mod flow;
pub mod fuzzing;
pub mod io;
pub mod model;
pub mod params;
pub mod render;
pub mod rng;
pub mod rtl;
pub mod scene;

//! Hardware cores: each builds its netlist from the parameters; its golden twin lives in
//! `model/`.

pub mod brom;
pub mod clock;
pub mod closest;
pub mod cost;
pub mod divider;
pub mod intersect;
pub mod mul;
pub mod plane;
pub mod raygen;
pub mod top;
pub mod traverse;

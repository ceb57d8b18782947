//! Hardware cores: each builds its netlist from the parameters; its golden twin lives in
//! `model/`.

pub mod divider;
pub mod intersect;
pub mod traverse;
pub mod closest;
pub mod top;

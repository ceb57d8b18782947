//! The models: the bit-exact golden integer model and the float references it is measured by.

pub mod camera;
pub mod checksum;
pub mod float;
pub mod golden;
pub mod ray;
pub mod raygen;
pub mod reference;

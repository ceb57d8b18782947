//! The on-chip pinhole ray generator's arithmetic, for a camera inside the scene box (the
//! thesis's demo): every ray starts at the eye's grid point, and the direction of pixel
//! (px, py) is the integer affine function d = d0 + px·dx + py·dy, fixed point with F fraction
//! bits. The host fits d0, dx, dy so the largest component over the frame is just below 1;
//! directions are not normalised (the hardware has no square root), which the intersection
//! arithmetic allows: t is then measured in units of |d| ≥ its largest component. The
//! reciprocals are `Golden::reciprocal`'s. `cores::raygen` computes exactly this.

use super::camera::Camera;
use super::golden::{Golden, GridRay};
use crate::scene::Scene;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RayGen {
    pub eye: [i64; 3],
    pub d0: [i64; 3],
    pub dx: [i64; 3],
    pub dy: [i64; 3],
    pub width: u32,
    pub height: u32,
}

impl RayGen {
    /// The generator for a camera given on the command line (inside the scene box); the error
    /// names the camera option at fault.
    pub fn for_camera(scene: &Scene, camera: &super::camera::CameraSpec) -> crate::error::Result<RayGen> {
        let cam = camera.camera(scene)?;
        RayGen::new(scene, &cam).map_err(|(opt, msg)| crate::error::Error::param(opt, msg))
    }

    /// The generator for `cam` in `scene`'s grid; the error names the camera option at fault.
    pub fn new(scene: &Scene, cam: &Camera) -> Result<RayGen, (&'static str, String)> {
        let hi = scene.grid_box.hi;
        let e = scene.transform.to_grid_f64(cam.eye);
        let eye: [i64; 3] = std::array::from_fn(|k| e[k].round() as i64);
        if (0..3).any(|k| !(0.0..=hi[k] as f64).contains(&e[k].round())) {
            return Err(("eye", "the ray generator needs the camera inside the scene box".into()));
        }
        let pr = cam.pixel_rays();
        let dir = |px: f64, py: f64| pr.unnormalized(px, py);
        let lim = (1i64 << (scene.params.m - 1)) - 1;
        let (w, h) = (cam.width as i64, cam.height as i64);
        let corners = [(0, 0), (w - 1, 0), (0, h - 1), (w - 1, h - 1)];
        let biggest = corners.iter().flat_map(|&(x, y)| dir(x as f64, y as f64)).fold(0.0f64, |a, c| a.max(c.abs()));
        let mut s = lim as f64 / biggest;
        for _ in 0..64 {
            let (a, b, c) = (dir(0.0, 0.0), dir(1.0, 0.0), dir(0.0, 1.0));
            let g = RayGen {
                eye,
                d0: std::array::from_fn(|k| (s * a[k]).round() as i64),
                // A one-pixel-wide (high) frame never steps in x (y): its step stays 0, and
                // with it the constant's width.
                dx: std::array::from_fn(|k| if w > 1 { (s * (b[k] - a[k])).round() as i64 } else { 0 }),
                dy: std::array::from_fn(|k| if h > 1 { (s * (c[k] - a[k])).round() as i64 } else { 0 }),
                width: cam.width,
                height: cam.height,
            };
            // Affine in (px, py): the corners bound every pixel.
            if corners.iter().all(|&(x, y)| g.direction(x as u32, y as u32).iter().all(|v| v.abs() <= lim)) {
                return Ok(g);
            }
            s *= 1.0 - 1.0 / 1024.0;
        }
        Err(("fov", "the field of view is too wide for the ray generator".into()))
    }

    pub fn direction(&self, px: u32, py: u32) -> [i64; 3] {
        std::array::from_fn(|k| self.d0[k] + px as i64 * self.dx[k] + py as i64 * self.dy[k])
    }

    pub fn ray(&self, g: &Golden, px: u32, py: u32) -> GridRay {
        g.ray(self.eye, self.direction(px, py))
    }
}

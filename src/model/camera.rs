//! The pinhole camera of `fxrt render` and of the on-chip ray generator, as the issue
//! specifies it: fov is vertical in degrees, py = 0 is the top row, and
//! sx = (2(px+0.5)/W − 1)·tan(fov/2)·W/H, sy = (1 − 2(py+0.5)/H)·tan(fov/2),
//! f = norm(at − eye), r = norm(f × up), u = r × f, dir = norm(f + sx·r + sy·u).

use crate::model::ray::{WorldRay, cross, normalize, sub};
use crate::scene::Scene;
use serde::{Deserialize, Serialize};

/// A camera as the user gives it; what is not given is chosen per scene (`Camera::default_for`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CameraSpec {
    pub eye: Option<[f64; 3]>,
    pub at: Option<[f64; 3]>,
    pub up: [f64; 3],
    pub fov: f64,
    pub width: u32,
    pub height: u32,
}

impl CameraSpec {
    /// The camera for `scene`; errors name the option at fault.
    pub fn camera(&self, scene: &Scene) -> crate::error::Result<Camera> {
        let mut cam = Camera::default_for(scene, self.width, self.height);
        if let Some(e) = self.eye {
            cam.eye = e;
        }
        if let Some(a) = self.at {
            cam.at = a;
        }
        cam.up = self.up;
        cam.fov_deg = self.fov;
        cam.validate().map_err(|(opt, msg)| match (opt, self.eye, self.at) {
            // Only --eye was given, and it is the point the camera looks at by default.
            ("at", Some(_), None) => crate::error::Error::param(
                "eye",
                "is the scene's centre, where the camera looks when --at is not given: give --at too",
            ),
            // Neither was given: the scene's own camera failed, which names the scene.
            ("eye" | "at", None, None) => {
                crate::error::Error::new(&scene.name, format!("the default camera cannot frame the scene: {msg}"))
            }
            _ => crate::error::Error::param(opt, msg),
        })?;
        Ok(cam)
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub eye: [f64; 3],
    pub at: [f64; 3],
    pub up: [f64; 3],
    pub fov_deg: f64,
    pub width: u32,
    pub height: u32,
}

impl Camera {
    /// Checks that the camera defines a basis; the message names the offending option.
    pub fn validate(&self) -> Result<(), (&'static str, String)> {
        let f = sub(self.at, self.eye);
        for (opt, v) in [("eye", self.eye), ("at", self.at), ("up", self.up)] {
            if v.iter().any(|x| !x.is_finite()) {
                return Err((opt, "camera coordinates must be finite".into()));
            }
        }
        if f == [0.0; 3] {
            return Err(("at", "must differ from --eye".into()));
        }
        if cross(f, self.up) == [0.0; 3] {
            return Err(("up", "must not be parallel to the view direction".into()));
        }
        if !(self.fov_deg > 0.0 && self.fov_deg < 180.0) {
            return Err(("fov", format!("{} is out of range: must be in (0, 180) degrees", self.fov_deg)));
        }
        Ok(())
    }

    pub fn ray(&self, px: u32, py: u32) -> WorldRay {
        self.pixel_rays().ray(px, py)
    }

    /// The per-frame part of `ray` (basis and tan), so a renderer computes it once.
    pub fn pixel_rays(&self) -> PixelRays {
        let f = normalize(sub(self.at, self.eye));
        let r = normalize(cross(f, self.up));
        let u = cross(r, f);
        let (w, h) = (self.width as f64, self.height as f64);
        PixelRays { eye: self.eye, w, h, tan: (self.fov_deg.to_radians() / 2.0).tan(), f, r, u }
    }

    /// The camera used when --eye/--at are not given: the published Cornell box camera for
    /// the built-in `cornell`, otherwise `framing`.
    pub fn default_for(scene: &Scene, width: u32, height: u32) -> Camera {
        if scene.name == "cornell" {
            // The Cornell Program of Computer Graphics' camera: 0.035 m focal length,
            // 0.025 m film, i.e. a 39.3° field of view, looking into the open side.
            let fov_deg = 2.0 * (0.0125f64 / 0.035).atan().to_degrees();
            return Camera {
                eye: [278.0, 273.0, -800.0],
                at: [278.0, 273.0, 0.0],
                up: [0.0, 1.0, 0.0],
                fov_deg,
                width,
                height,
            };
        }
        Camera::framing(scene, width, height)
    }

    /// A camera inside the scene box, for the on-chip ray generator: at the middle of the
    /// box's front (2 % of its depth in from the −z face), looking at its centre.
    pub fn inside(scene: &Scene, width: u32, height: u32, fov_deg: f64) -> Camera {
        let (lo, hi) = world_bounds(scene);
        let at: [f64; 3] = std::array::from_fn(|k| 0.5 * (lo[k] + hi[k]));
        let eye = [at[0], at[1], lo[2] + 0.02 * (hi[2] - lo[2])];
        Camera { eye, at, up: [0.0, 1.0, 0.0], fov_deg, width, height }
    }

    /// A camera that frames the whole scene from the front (−z), right and above.
    pub fn framing(scene: &Scene, width: u32, height: u32) -> Camera {
        let (lo, hi) = world_bounds(scene);
        let at: [f64; 3] = std::array::from_fn(|k| 0.5 * (lo[k] + hi[k]));
        let radius = 0.5 * (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
        let fov_deg: f64 = 45.0;
        let dist = 0.8 * radius / (fov_deg.to_radians() / 2.0).sin();
        let dir = normalize([0.5, 0.4, -1.0]);
        let eye = std::array::from_fn(|k| at[k] + dist * dir[k]);
        Camera { eye, at, up: [0.0, 1.0, 0.0], fov_deg, width, height }
    }
}

/// A camera's primary rays: `ray` gives bit for bit what `Camera::ray` specifies.
#[derive(Clone, Copy, Debug)]
pub struct PixelRays {
    eye: [f64; 3],
    w: f64,
    h: f64,
    tan: f64,
    f: [f64; 3],
    r: [f64; 3],
    u: [f64; 3],
}

impl PixelRays {
    /// f + sx·r + sy·u for the pixel position (px, py) (pixel centres at integer + 0.5).
    pub fn unnormalized(&self, px: f64, py: f64) -> [f64; 3] {
        let (w, h, tan) = (self.w, self.h, self.tan);
        let sx = (2.0 * (px + 0.5) / w - 1.0) * tan * w / h;
        let sy = (1.0 - 2.0 * (py + 0.5) / h) * tan;
        std::array::from_fn(|k| self.f[k] + sx * self.r[k] + sy * self.u[k])
    }

    #[inline]
    pub fn ray(&self, px: u32, py: u32) -> WorldRay {
        let (w, h, tan) = (self.w, self.h, self.tan);
        let sx = (2.0 * (px as f64 + 0.5) / w - 1.0) * tan * w / h;
        let sy = (1.0 - 2.0 * (py as f64 + 0.5) / h) * tan;
        let d = normalize(std::array::from_fn(|k| self.f[k] + sx * self.r[k] + sy * self.u[k]));
        WorldRay { o: self.eye, d }
    }
}

/// The world-space bounding box of the scene's input triangles.
pub fn world_bounds(scene: &Scene) -> ([f64; 3], [f64; 3]) {
    crate::scene::world_box(&scene.world)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_pixel_looks_at_target_and_top_row_looks_up() {
        let c = Camera { eye: [0.0, 0.0, 5.0], at: [0.0; 3], up: [0.0, 1.0, 0.0], fov_deg: 90.0, width: 3, height: 3 };
        let mid = c.ray(1, 1).d;
        assert!((mid[2] + 1.0).abs() < 1e-12 && mid[0].abs() < 1e-12);
        let top = c.ray(1, 0).d;
        assert!(top[1] > 0.0);
        let right = c.ray(2, 1).d;
        assert!(right[0] > 0.0);
        // tan(45°) · 2/3 off-centre at the edge pixel centre.
        assert!((top[1] / -top[2] - 2.0 / 3.0).abs() < 1e-12);
    }

    /// At the scene limits (`scene::MAX_COORDINATE`, `MIN_EXTENT`) the default camera frames
    /// the scene: finite, eye apart from at (a 1e-310 extent used to fail as "--at").
    #[test]
    fn the_default_camera_frames_scenes_at_the_limits() {
        use crate::scene::{MAX_COORDINATE, MIN_EXTENT};
        let spec = CameraSpec { eye: None, at: None, up: [0.0, 1.0, 0.0], fov: 45.0, width: 4, height: 4 };
        for (a, b) in [(-MAX_COORDINATE, MAX_COORDINATE), (0.0, MIN_EXTENT), (-MIN_EXTENT, 0.0)] {
            let tris = vec![[[a, a, a], [b, a, a], [a, b, b]]];
            let s = Scene::build("s", tris, &crate::params::Params::default()).unwrap();
            let cam = spec.camera(&s).unwrap();
            assert!(cam.eye != cam.at && cam.ray(0, 0).d.iter().all(|x| x.is_finite()), "{cam:?}");
        }
    }

    /// Errors name the option the user gave, or the scene when the camera is its default.
    #[test]
    fn camera_errors_name_the_real_cause() {
        let tris = vec![[[0., 0., 0.], [2., 0., 0.], [0., 2., 2.]]];
        let s = Scene::build("s.obj", tris, &crate::params::Params::default()).unwrap();
        let spec =
            CameraSpec { eye: Some([1.0, 1.0, 1.0]), at: None, up: [0.0, 1.0, 0.0], fov: 45.0, width: 4, height: 4 };
        let e = spec.camera(&s).unwrap_err().to_string();
        assert!(e.starts_with("--eye: is the scene's centre"), "{e}");
        let spec = CameraSpec { eye: None, up: [0.0, f64::INFINITY, 0.0], ..spec };
        assert!(spec.camera(&s).unwrap_err().to_string().starts_with("--up: "));
        let spec = CameraSpec { at: Some([f64::NAN, 0.0, 0.0]), up: [0.0, 1.0, 0.0], ..spec };
        assert!(spec.camera(&s).unwrap_err().to_string().starts_with("--at: "));
    }

    #[test]
    fn degenerate_cameras_are_rejected() {
        let c = Camera { eye: [0.0; 3], at: [0.0; 3], up: [0.0, 1.0, 0.0], fov_deg: 45.0, width: 1, height: 1 };
        assert_eq!(c.validate().unwrap_err().0, "at");
        let c = Camera { at: [0.0, 1.0, 0.0], ..c };
        assert_eq!(c.validate().unwrap_err().0, "up");
        let c = Camera { at: [1.0, 0.0, 0.0], fov_deg: 180.0, ..c };
        assert_eq!(c.validate().unwrap_err().0, "fov");
    }
}

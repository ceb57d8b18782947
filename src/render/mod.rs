//! `fxrt render`: one primary ray per pixel through any of the models, in parallel; and
//! Embree's side of `fxrt bench --against-embree` (`embree`), the CPU tracer the golden
//! model's speed is measured against.

pub mod compare;
pub mod embree;
pub mod fast;
pub mod tracer;

use crate::model::camera::Camera;
use crate::model::ray::{cross, dot, normalize, sub};
use crate::scene::Scene;
use rayon::prelude::*;
use tracer::Tracer;

/// What one frame produced. `ids` and `depth` are row-major, py = 0 at the top.
pub struct Frame {
    pub width: u32,
    pub height: u32,
    /// Input triangle number per pixel, −1 for a miss.
    pub ids: Vec<i32>,
    /// World-space distance from the eye, +inf for a miss.
    pub depth: Vec<f64>,
    /// Brightness in [0, 1] for the picture.
    pub shade: Vec<f32>,
    pub rays: u64,
    pub hits: u64,
    pub seconds: f64,
}

/// A point light near the eye: up and to the right of it by 15 % of the viewing distance.
pub fn light_position(cam: &Camera) -> [f64; 3] {
    let fwd = sub(cam.at, cam.eye);
    let dist = dot(fwd, fwd).sqrt();
    let f = normalize(fwd);
    let r = normalize(cross(f, cam.up));
    let u = cross(r, f);
    std::array::from_fn(|k| cam.eye[k] + 0.15 * dist * (r[k] + u[k]))
}

/// Each input triangle's unit normal (world space), by triangle number.
pub fn world_normals(scene: &Scene) -> Vec<[f64; 3]> {
    scene.world.iter().map(|t| normalize(cross(sub(t[1], t[0]), sub(t[2], t[0])))).collect()
}

/// The unshadowed brightness of a surface of normal `n` seen along `d` (a headlight).
pub fn headlight(n: [f64; 3], d: [f64; 3]) -> f64 {
    0.12 + 0.88 * dot(n, d).abs()
}

pub fn render(scene: &Scene, tracer: &dyn Tracer, cam: &Camera, shade: bool, progress: bool) -> Frame {
    let (w, h) = (cam.width, cam.height);
    let light = light_position(cam);
    let normals = world_normals(scene);
    let bar = if progress && (w as u64) * (h as u64) >= 1 << 18 {
        indicatif::ProgressBar::new(h as u64)
    } else {
        indicatif::ProgressBar::hidden()
    };
    bar.set_style(
        indicatif::ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} rows ({eta})")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    bar.set_message("render");
    let start = std::time::Instant::now();
    let pixel_rays = cam.pixel_rays();
    let rows: Vec<Vec<(i32, f64, f32, u8)>> = (0..h)
        .into_par_iter()
        .map(|py| {
            let rays: Vec<_> = (0..w).map(|px| pixel_rays.ray(px, py)).collect();
            let mut row = vec![(-1, f64::INFINITY, -1.0, 1); w as usize];
            tracer.primary_row(&rays, &mut |px, hit| {
                let (ray, n) = (&rays[px], normals[hit.id as usize]);
                let (brightness, traced) = if shade {
                    let p: [f64; 3] = std::array::from_fn(|k| ray.o[k] + hit.dist * ray.d[k]);
                    let l = normalize(sub(light, p));
                    let lit = !tracer.shadowed(ray, &hit, light);
                    (0.12 + if lit { 0.88 * dot(n, l).abs() } else { 0.0 }, 2)
                } else {
                    (headlight(n, ray.d), 1)
                };
                row[px] = (hit.id as i32, hit.dist, brightness as f32, traced);
            });
            bar.inc(1);
            row
        })
        .collect();
    bar.finish_and_clear();
    let seconds = start.elapsed().as_secs_f64();
    let px = rows.into_iter().flatten();
    let mut f = Frame { width: w, height: h, ids: vec![], depth: vec![], shade: vec![], rays: 0, hits: 0, seconds };
    for (id, d, s, rays) in px {
        f.ids.push(id);
        f.depth.push(d);
        f.shade.push(s);
        f.rays += rays as u64;
        f.hits += (id >= 0) as u64;
    }
    f
}

impl Frame {
    pub fn ids_bytes(&self) -> Vec<u8> {
        self.ids.iter().flat_map(|x| x.to_le_bytes()).collect()
    }
    pub fn depth_bytes(&self) -> Vec<u8> {
        self.depth.iter().flat_map(|&x| (x as f32).to_le_bytes()).collect()
    }
    /// An 8-bit RGB PNG: warm grey surfaces, a dark blue-grey background.
    pub fn png_bytes(&self) -> Vec<u8> {
        let mut rgb = Vec::with_capacity(self.shade.len() * 3);
        for &s in &self.shade {
            if s < 0.0 {
                rgb.extend_from_slice(&[22, 26, 34]);
            } else {
                let s = s.clamp(0.0, 1.0);
                rgb.extend_from_slice(&[(20.0 + 235.0 * s) as u8, (20.0 + 220.0 * s) as u8, (24.0 + 196.0 * s) as u8]);
            }
        }
        encode_png(self.width, self.height, &rgb)
    }
}

/// Encodes 8-bit RGB pixels as PNG in memory (so the file can be written atomically).
pub fn encode_png(width: u32, height: u32, rgb: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, width, height);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        // Writing into a Vec cannot fail; the data length matches width·height·3 by construction.
        let mut w = enc.write_header().expect("png header into memory");
        w.write_image_data(rgb).expect("png data into memory");
    }
    out
}

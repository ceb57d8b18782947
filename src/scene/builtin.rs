//! Built-in test scenes, generated in code as triangle soups in world space.
//!
//! All scenes are deterministic: randomness comes only from a fixed-seed
//! SplitMix64, and the arithmetic is plain f64 (plus `sin`/`cos` for the
//! jackstraws), so the same build produces bit-identical triangles every run.

use std::array::from_fn;
use std::f64::consts::TAU;

/// A triangle as three world-space vertices.
pub type Tri = [[f64; 3]; 3];

/// Names accepted by `--builtin`, in the order help text lists them.
pub const BUILTIN_NAMES: &[&str] = &["teapot", "jackstraws", "thin", "random", "cornell", "teapot-fine"];

/// One-line description per name (same order), for `--help`.
pub const BUILTIN_DESCRIPTIONS: &[&str] = &[
    "Utah teapot: Newell's 32 Bezier patches as 6,320 triangles, y up",
    "12 crossing sticks (cylinders r=0.01, length 2), 2,048 long narrow triangles each",
    "near-worst-case sliver across the scene box diagonal, plus floor and back wall",
    "2,000 small random triangles in the unit cube",
    "Cornell box from the measured Cornell data (mm), light quad included",
    "the Utah teapot tessellated three times finer: 57,360 triangles (a 50k+ scene)",
];

/// `builtin_scene`, or the error naming the known scenes.
pub fn load(name: &str) -> crate::error::Result<Vec<Tri>> {
    builtin_scene(name).ok_or_else(|| {
        crate::error::Error::param("builtin", format!("unknown scene '{name}'; known: {}", BUILTIN_NAMES.join(", ")))
    })
}

/// The triangles of a built-in scene, numbered in the returned order; None for an unknown name.
pub fn builtin_scene(name: &str) -> Option<Vec<Tri>> {
    let tris = match name {
        "teapot" => teapot(TEAPOT_K),
        "teapot-fine" => teapot(3 * TEAPOT_K),
        "jackstraws" => jackstraws(),
        "thin" => thin(),
        "random" => random(),
        "cornell" => cornell(),
        _ => return None,
    };
    Some(tris)
}

// ---------------------------------------------------------------------------
// Small vector helpers

type V3 = [f64; 3];

fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn scale(a: V3, s: f64) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

fn cross(a: V3, b: V3) -> V3 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

fn normalize(a: V3) -> V3 {
    scale(a, 1.0 / (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt())
}

/// True if two vertices coincide or the area is exactly zero in f64.
fn is_degenerate(t: &Tri) -> bool {
    t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || cross(sub(t[1], t[0]), sub(t[2], t[0])) == [0.0; 3]
}

/// Appends the quad `v0 v1 v2 v3` as the triangles (v0,v1,v2) and (v0,v2,v3).
fn push_quad(tris: &mut Vec<Tri>, [v0, v1, v2, v3]: [V3; 4]) {
    tris.push([v0, v1, v2]);
    tris.push([v0, v2, v3]);
}

use crate::rng::SplitMix64;

/// Extra draws the scenes need on top of the shared generator.
trait Directions {
    fn unit_vector(&mut self) -> V3;
}

impl Directions for SplitMix64 {
    /// Uniformly distributed direction: by Archimedes' hat-box theorem a
    /// uniform height and a uniform azimuth cover the sphere uniformly.
    fn unit_vector(&mut self) -> V3 {
        let z = self.range(-1.0, 1.0);
        let phi = TAU * self.next_f64();
        let r = (1.0 - z * z).sqrt();
        [r * phi.cos(), r * phi.sin(), z]
    }
}

// ---------------------------------------------------------------------------
// teapot

/// Quads per patch side. 32 patches x 10 x 10 quads x 2 = 6,400 triangles,
/// of which 80 are dropped: the first control row of each of the 4 lid-knob
/// and 4 bottom patches collapses to a single point, so one triangle of every
/// quad along that edge degenerates.
const TEAPOT_K: usize = 10;

/// Newell's data has z up; we rotate to y up with (x, y, z) -> (x, z, -y), a
/// proper rotation (-90 degrees about x). The teapot then stands on y = 0 with
/// the spout towards +x and the handle towards -x. (`0.0 - y` rather than `-y`
/// avoids negative zeros.)
fn z_up_to_y_up([x, y, z]: V3) -> V3 {
    [x, z, 0.0 - y]
}

/// `s * a + t * b` per coordinate, for weights with s + t = 1 (up to
/// rounding). It is symmetric under swapping (a, s) with (b, t), exact at the
/// end points, and exactly `a` where `a` and `b` agree.
fn blend(a: V3, b: V3, s: f64, t: f64) -> V3 {
    from_fn(|k| if a[k] == b[k] { a[k] } else { s * a[k] + t * b[k] })
}

/// Point at parameter `i / n` on a cubic Bezier curve, by de Casteljau's
/// algorithm. Thanks to `blend`, the end points come out exactly, a reversed
/// curve at `(n - i) / n` gives the same bits (so patches share bit-identical
/// edge vertices whatever their orientation), and coincident control points
/// yield exactly that point (so the lid and bottom apexes really collapse).
fn bezier_curve(mut c: [V3; 4], i: usize, n: usize) -> V3 {
    let (s, t) = ((n - i) as f64 / n as f64, i as f64 / n as f64);
    for level in (1..4).rev() {
        for j in 0..level {
            c[j] = blend(c[j], c[j + 1], s, t);
        }
    }
    c[0]
}

/// Point at (u, v) = (i / n, j / n) on a bicubic Bezier patch; control point
/// `4 * row + col`, the row following `u` and the column following `v`.
fn bezier_patch(ctrl: &[V3; 16], i: usize, j: usize, n: usize) -> V3 {
    let rows = from_fn(|r| bezier_curve(from_fn(|c| ctrl[4 * r + c]), j, n));
    bezier_curve(rows, i, n)
}

/// The 16 control points of a patch (the table holds 1-based indices).
fn teapot_patch(patch: &[u16; 16]) -> [V3; 16] {
    patch.map(|i| TEAPOT_POINTS[usize::from(i) - 1])
}

/// Newell's patches, each as an n × n grid of quads split into two triangles.
fn teapot(n: usize) -> Vec<Tri> {
    let at = |i: usize, j: usize| i * (n + 1) + j;
    let mut tris = Vec::with_capacity(TEAPOT_PATCHES.len() * n * n * 2);
    let mut grid = vec![[0.0; 3]; (n + 1) * (n + 1)];
    for patch in &TEAPOT_PATCHES {
        let ctrl = teapot_patch(patch);
        for i in 0..=n {
            for j in 0..=n {
                grid[at(i, j)] = z_up_to_y_up(bezier_patch(&ctrl, i, j, n));
            }
        }
        for i in 0..n {
            for j in 0..n {
                let (p00, p01) = (grid[at(i, j)], grid[at(i, j + 1)]);
                let (p10, p11) = (grid[at(i + 1, j)], grid[at(i + 1, j + 1)]);
                for tri in [[p00, p10, p11], [p00, p11, p01]] {
                    if !is_degenerate(&tri) {
                        tris.push(tri);
                    }
                }
            }
        }
    }
    tris
}

// ---------------------------------------------------------------------------
// jackstraws

const STICKS: usize = 12;
const STICK_RADIUS: f64 = 0.01;
const STICK_HALF_LENGTH: f64 = 1.0;
/// Segments around each stick; with a single segment along its length every
/// triangle is 2.0 long but only 2*pi*0.01/1024 = 6e-5 wide.
const STICK_SEGMENTS: usize = 1024;

/// Two unit vectors that together with the unit vector `d` form an orthonormal basis.
fn perpendicular_basis(d: V3) -> (V3, V3) {
    // Crossing with the coordinate axis least aligned with `d` is always well conditioned.
    let a = d.map(f64::abs);
    let helper = if a[0] <= a[1] && a[0] <= a[2] {
        [1.0, 0.0, 0.0]
    } else if a[1] <= a[2] {
        [0.0, 1.0, 0.0]
    } else {
        [0.0, 0.0, 1.0]
    };
    let e1 = normalize(cross(d, helper));
    (e1, cross(d, e1))
}

/// The thesis's stress test: a pile of long, thin open cylinders ("mikado
/// sticks") crossing each other, whose bounding boxes overlap heavily.
fn jackstraws() -> Vec<Tri> {
    let mut rng = SplitMix64(0x6A61_636B_7374_7261); // "jackstra"
    let mut tris = Vec::with_capacity(STICKS * 2 * STICK_SEGMENTS);
    for _ in 0..STICKS {
        let axis = rng.unit_vector();
        // Along coordinate k the centre may move by 1 - |axis[k]| without an
        // end leaving [-1, 1]^3; use half that room so the sticks bunch up
        // and cross near the middle.
        let centre: V3 = from_fn(|k| 0.5 * (1.0 - axis[k].abs()) * rng.range(-1.0, 1.0));
        let (e1, e2) = perpendicular_basis(axis);
        let ends = [sub(centre, scale(axis, STICK_HALF_LENGTH)), add(centre, scale(axis, STICK_HALF_LENGTH))];
        let ring: Vec<V3> = (0..STICK_SEGMENTS)
            .map(|s| {
                let theta = TAU * s as f64 / STICK_SEGMENTS as f64;
                add(scale(e1, STICK_RADIUS * theta.cos()), scale(e2, STICK_RADIUS * theta.sin()))
            })
            .collect();
        for s in 0..STICK_SEGMENTS {
            let (o0, o1) = (ring[s], ring[(s + 1) % STICK_SEGMENTS]);
            let (a0, a1) = (add(ends[0], o0), add(ends[0], o1));
            let (b0, b1) = (add(ends[1], o0), add(ends[1], o1));
            tris.push([a0, a1, b1]);
            tris.push([a0, b1, b0]);
        }
    }
    tris
}

// ---------------------------------------------------------------------------
// thin

/// The near-worst-case triangle of the thesis (section 2.5.1): a sliver whose
/// bounding box is the whole scene box, so it overlaps every cell of any
/// spatial subdivision, while covering almost no area (it renders as a line).
fn thin() -> Vec<Tri> {
    // An open frame that fixes the scene box to [0,1]^3 on its own:
    // a floor at y = 0 and a back wall at z = 1.
    #[rustfmt::skip]
    const FRAME: [[V3; 4]; 2] = [
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 1.0], [0.0, 0.0, 1.0]],
        [[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [1.0, 1.0, 1.0], [0.0, 1.0, 1.0]],
    ];
    let mut tris = Vec::with_capacity(5);
    for quad in FRAME {
        push_quad(&mut tris, quad);
    }
    // Corner to opposite corner, apex ~1.4e-3 off the box centre in the
    // direction (1, 0, -1), which is perpendicular to the diagonal.
    tris.push([[0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [0.501, 0.5, 0.499]]);
    tris
}

// ---------------------------------------------------------------------------
// random

const RANDOM_TRIANGLES: usize = 2000;
const RANDOM_HALF_SIZE: f64 = 0.05;

/// Small triangles with independent random vertices around random centres in [0,1]^3.
fn random() -> Vec<Tri> {
    let mut rng = SplitMix64(0x7261_6E64_6F6D_5F74); // "random_t"
    let mut tris = Vec::with_capacity(RANDOM_TRIANGLES);
    while tris.len() < RANDOM_TRIANGLES {
        let centre: V3 = from_fn(|_| rng.next_f64());
        let tri: Tri = from_fn(|_| from_fn(|k| centre[k] + rng.range(-RANDOM_HALF_SIZE, RANDOM_HALF_SIZE)));
        // A degenerate draw is practically impossible, but the count must stay exact.
        if !is_degenerate(&tri) {
            tris.push(tri);
        }
    }
    tris
}

// ---------------------------------------------------------------------------
// cornell

/// The Cornell box as measured by the Cornell Program of Computer Graphics
/// ("Cornell Box Data", graphics.cornell.edu), in millimetres, y up, the
/// camera looking along +z. Quads in the order: floor, ceiling, light, back
/// wall, right wall (green, x = 0), left wall (red, x ~ 556), short block
/// (5 quads), tall block (5 quads). So triangles 4 and 5 are the light; as in
/// the published data it lies in the ceiling plane (y = 548.8).
#[rustfmt::skip]
const CORNELL_QUADS: [[V3; 4]; 16] = [
    // floor
    [[552.8, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 559.2], [549.6, 0.0, 559.2]],
    // ceiling
    [[556.0, 548.8, 0.0], [556.0, 548.8, 559.2], [0.0, 548.8, 559.2], [0.0, 548.8, 0.0]],
    // light
    [[343.0, 548.8, 227.0], [343.0, 548.8, 332.0], [213.0, 548.8, 332.0], [213.0, 548.8, 227.0]],
    // back wall
    [[549.6, 0.0, 559.2], [0.0, 0.0, 559.2], [0.0, 548.8, 559.2], [556.0, 548.8, 559.2]],
    // right wall
    [[0.0, 0.0, 559.2], [0.0, 0.0, 0.0], [0.0, 548.8, 0.0], [0.0, 548.8, 559.2]],
    // left wall
    [[552.8, 0.0, 0.0], [549.6, 0.0, 559.2], [556.0, 548.8, 559.2], [556.0, 548.8, 0.0]],
    // short block
    [[130.0, 165.0, 65.0], [82.0, 165.0, 225.0], [240.0, 165.0, 272.0], [290.0, 165.0, 114.0]],
    [[290.0, 0.0, 114.0], [290.0, 165.0, 114.0], [240.0, 165.0, 272.0], [240.0, 0.0, 272.0]],
    [[130.0, 0.0, 65.0], [130.0, 165.0, 65.0], [290.0, 165.0, 114.0], [290.0, 0.0, 114.0]],
    [[82.0, 0.0, 225.0], [82.0, 165.0, 225.0], [130.0, 165.0, 65.0], [130.0, 0.0, 65.0]],
    [[240.0, 0.0, 272.0], [240.0, 165.0, 272.0], [82.0, 165.0, 225.0], [82.0, 0.0, 225.0]],
    // tall block
    [[423.0, 330.0, 247.0], [265.0, 330.0, 296.0], [314.0, 330.0, 456.0], [472.0, 330.0, 406.0]],
    [[423.0, 0.0, 247.0], [423.0, 330.0, 247.0], [472.0, 330.0, 406.0], [472.0, 0.0, 406.0]],
    [[472.0, 0.0, 406.0], [472.0, 330.0, 406.0], [314.0, 330.0, 456.0], [314.0, 0.0, 456.0]],
    [[314.0, 0.0, 456.0], [314.0, 330.0, 456.0], [265.0, 330.0, 296.0], [265.0, 0.0, 296.0]],
    [[265.0, 0.0, 296.0], [265.0, 330.0, 296.0], [423.0, 330.0, 247.0], [423.0, 0.0, 247.0]],
];

fn cornell() -> Vec<Tri> {
    let mut tris = Vec::with_capacity(2 * CORNELL_QUADS.len());
    for quad in CORNELL_QUADS {
        push_quad(&mut tris, quad);
    }
    tris
}

// ---------------------------------------------------------------------------
// Utah teapot data

/// Martin Newell's Utah teapot (1975, public domain): 306 control points,
/// z up, as in the widely circulated `teapot` data file (e.g. in k3d/Aqsis
/// and many OpenGL samples).
#[rustfmt::skip]
const TEAPOT_POINTS: [V3; 306] = [
    [1.4, 0.0, 2.4], [1.4, -0.784, 2.4], [0.784, -1.4, 2.4], [0.0, -1.4, 2.4],
    [1.3375, 0.0, 2.53125], [1.3375, -0.749, 2.53125], [0.749, -1.3375, 2.53125], [0.0, -1.3375, 2.53125],
    [1.4375, 0.0, 2.53125], [1.4375, -0.805, 2.53125], [0.805, -1.4375, 2.53125], [0.0, -1.4375, 2.53125],
    [1.5, 0.0, 2.4], [1.5, -0.84, 2.4], [0.84, -1.5, 2.4], [0.0, -1.5, 2.4],
    [-0.784, -1.4, 2.4], [-1.4, -0.784, 2.4], [-1.4, 0.0, 2.4], [-0.749, -1.3375, 2.53125],
    [-1.3375, -0.749, 2.53125], [-1.3375, 0.0, 2.53125], [-0.805, -1.4375, 2.53125], [-1.4375, -0.805, 2.53125],
    [-1.4375, 0.0, 2.53125], [-0.84, -1.5, 2.4], [-1.5, -0.84, 2.4], [-1.5, 0.0, 2.4],
    [-1.4, 0.784, 2.4], [-0.784, 1.4, 2.4], [0.0, 1.4, 2.4], [-1.3375, 0.749, 2.53125],
    [-0.749, 1.3375, 2.53125], [0.0, 1.3375, 2.53125], [-1.4375, 0.805, 2.53125], [-0.805, 1.4375, 2.53125],
    [0.0, 1.4375, 2.53125], [-1.5, 0.84, 2.4], [-0.84, 1.5, 2.4], [0.0, 1.5, 2.4],
    [0.784, 1.4, 2.4], [1.4, 0.784, 2.4], [0.749, 1.3375, 2.53125], [1.3375, 0.749, 2.53125],
    [0.805, 1.4375, 2.53125], [1.4375, 0.805, 2.53125], [0.84, 1.5, 2.4], [1.5, 0.84, 2.4],
    [1.75, 0.0, 1.875], [1.75, -0.98, 1.875], [0.98, -1.75, 1.875], [0.0, -1.75, 1.875],
    [2.0, 0.0, 1.35], [2.0, -1.12, 1.35], [1.12, -2.0, 1.35], [0.0, -2.0, 1.35],
    [2.0, 0.0, 0.9], [2.0, -1.12, 0.9], [1.12, -2.0, 0.9], [0.0, -2.0, 0.9],
    [-0.98, -1.75, 1.875], [-1.75, -0.98, 1.875], [-1.75, 0.0, 1.875], [-1.12, -2.0, 1.35],
    [-2.0, -1.12, 1.35], [-2.0, 0.0, 1.35], [-1.12, -2.0, 0.9], [-2.0, -1.12, 0.9],
    [-2.0, 0.0, 0.9], [-1.75, 0.98, 1.875], [-0.98, 1.75, 1.875], [0.0, 1.75, 1.875],
    [-2.0, 1.12, 1.35], [-1.12, 2.0, 1.35], [0.0, 2.0, 1.35], [-2.0, 1.12, 0.9],
    [-1.12, 2.0, 0.9], [0.0, 2.0, 0.9], [0.98, 1.75, 1.875], [1.75, 0.98, 1.875],
    [1.12, 2.0, 1.35], [2.0, 1.12, 1.35], [1.12, 2.0, 0.9], [2.0, 1.12, 0.9],
    [2.0, 0.0, 0.45], [2.0, -1.12, 0.45], [1.12, -2.0, 0.45], [0.0, -2.0, 0.45],
    [1.5, 0.0, 0.225], [1.5, -0.84, 0.225], [0.84, -1.5, 0.225], [0.0, -1.5, 0.225],
    [1.5, 0.0, 0.15], [1.5, -0.84, 0.15], [0.84, -1.5, 0.15], [0.0, -1.5, 0.15],
    [-1.12, -2.0, 0.45], [-2.0, -1.12, 0.45], [-2.0, 0.0, 0.45], [-0.84, -1.5, 0.225],
    [-1.5, -0.84, 0.225], [-1.5, 0.0, 0.225], [-0.84, -1.5, 0.15], [-1.5, -0.84, 0.15],
    [-1.5, 0.0, 0.15], [-2.0, 1.12, 0.45], [-1.12, 2.0, 0.45], [0.0, 2.0, 0.45],
    [-1.5, 0.84, 0.225], [-0.84, 1.5, 0.225], [0.0, 1.5, 0.225], [-1.5, 0.84, 0.15],
    [-0.84, 1.5, 0.15], [0.0, 1.5, 0.15], [1.12, 2.0, 0.45], [2.0, 1.12, 0.45],
    [0.84, 1.5, 0.225], [1.5, 0.84, 0.225], [0.84, 1.5, 0.15], [1.5, 0.84, 0.15],
    [-1.6, 0.0, 2.025], [-1.6, -0.3, 2.025], [-1.5, -0.3, 2.25], [-1.5, 0.0, 2.25],
    [-2.3, 0.0, 2.025], [-2.3, -0.3, 2.025], [-2.5, -0.3, 2.25], [-2.5, 0.0, 2.25],
    [-2.7, 0.0, 2.025], [-2.7, -0.3, 2.025], [-3.0, -0.3, 2.25], [-3.0, 0.0, 2.25],
    [-2.7, 0.0, 1.8], [-2.7, -0.3, 1.8], [-3.0, -0.3, 1.8], [-3.0, 0.0, 1.8],
    [-1.5, 0.3, 2.25], [-1.6, 0.3, 2.025], [-2.5, 0.3, 2.25], [-2.3, 0.3, 2.025],
    [-3.0, 0.3, 2.25], [-2.7, 0.3, 2.025], [-3.0, 0.3, 1.8], [-2.7, 0.3, 1.8],
    [-2.7, 0.0, 1.575], [-2.7, -0.3, 1.575], [-3.0, -0.3, 1.35], [-3.0, 0.0, 1.35],
    [-2.5, 0.0, 1.125], [-2.5, -0.3, 1.125], [-2.65, -0.3, 0.9375], [-2.65, 0.0, 0.9375],
    [-2.0, -0.3, 0.9], [-1.9, -0.3, 0.6], [-1.9, 0.0, 0.6], [-3.0, 0.3, 1.35],
    [-2.7, 0.3, 1.575], [-2.65, 0.3, 0.9375], [-2.5, 0.3, 1.125], [-1.9, 0.3, 0.6],
    [-2.0, 0.3, 0.9], [1.7, 0.0, 1.425], [1.7, -0.66, 1.425], [1.7, -0.66, 0.6],
    [1.7, 0.0, 0.6], [2.6, 0.0, 1.425], [2.6, -0.66, 1.425], [3.1, -0.66, 0.825],
    [3.1, 0.0, 0.825], [2.3, 0.0, 2.1], [2.3, -0.25, 2.1], [2.4, -0.25, 2.025],
    [2.4, 0.0, 2.025], [2.7, 0.0, 2.4], [2.7, -0.25, 2.4], [3.3, -0.25, 2.4],
    [3.3, 0.0, 2.4], [1.7, 0.66, 0.6], [1.7, 0.66, 1.425], [3.1, 0.66, 0.825],
    [2.6, 0.66, 1.425], [2.4, 0.25, 2.025], [2.3, 0.25, 2.1], [3.3, 0.25, 2.4],
    [2.7, 0.25, 2.4], [2.8, 0.0, 2.475], [2.8, -0.25, 2.475], [3.525, -0.25, 2.49375],
    [3.525, 0.0, 2.49375], [2.9, 0.0, 2.475], [2.9, -0.15, 2.475], [3.45, -0.15, 2.5125],
    [3.45, 0.0, 2.5125], [2.8, 0.0, 2.4], [2.8, -0.15, 2.4], [3.2, -0.15, 2.4],
    [3.2, 0.0, 2.4], [3.525, 0.25, 2.49375], [2.8, 0.25, 2.475], [3.45, 0.15, 2.5125],
    [2.9, 0.15, 2.475], [3.2, 0.15, 2.4], [2.8, 0.15, 2.4], [0.0, 0.0, 3.15],
    [0.0, -0.002, 3.15], [0.002, 0.0, 3.15], [0.8, 0.0, 3.15], [0.8, -0.45, 3.15],
    [0.45, -0.8, 3.15], [0.0, -0.8, 3.15], [0.0, 0.0, 2.85], [0.2, 0.0, 2.7],
    [0.2, -0.112, 2.7], [0.112, -0.2, 2.7], [0.0, -0.2, 2.7], [-0.002, 0.0, 3.15],
    [-0.45, -0.8, 3.15], [-0.8, -0.45, 3.15], [-0.8, 0.0, 3.15], [-0.112, -0.2, 2.7],
    [-0.2, -0.112, 2.7], [-0.2, 0.0, 2.7], [0.0, 0.002, 3.15], [-0.8, 0.45, 3.15],
    [-0.45, 0.8, 3.15], [0.0, 0.8, 3.15], [-0.2, 0.112, 2.7], [-0.112, 0.2, 2.7],
    [0.0, 0.2, 2.7], [0.45, 0.8, 3.15], [0.8, 0.45, 3.15], [0.112, 0.2, 2.7],
    [0.2, 0.112, 2.7], [0.4, 0.0, 2.55], [0.4, -0.224, 2.55], [0.224, -0.4, 2.55],
    [0.0, -0.4, 2.55], [1.3, 0.0, 2.55], [1.3, -0.728, 2.55], [0.728, -1.3, 2.55],
    [0.0, -1.3, 2.55], [1.3, 0.0, 2.4], [1.3, -0.728, 2.4], [0.728, -1.3, 2.4],
    [0.0, -1.3, 2.4], [-0.224, -0.4, 2.55], [-0.4, -0.224, 2.55], [-0.4, 0.0, 2.55],
    [-0.728, -1.3, 2.55], [-1.3, -0.728, 2.55], [-1.3, 0.0, 2.55], [-0.728, -1.3, 2.4],
    [-1.3, -0.728, 2.4], [-1.3, 0.0, 2.4], [-0.4, 0.224, 2.55], [-0.224, 0.4, 2.55],
    [0.0, 0.4, 2.55], [-1.3, 0.728, 2.55], [-0.728, 1.3, 2.55], [0.0, 1.3, 2.55],
    [-1.3, 0.728, 2.4], [-0.728, 1.3, 2.4], [0.0, 1.3, 2.4], [0.224, 0.4, 2.55],
    [0.4, 0.224, 2.55], [0.728, 1.3, 2.55], [1.3, 0.728, 2.55], [0.728, 1.3, 2.4],
    [1.3, 0.728, 2.4], [0.0, 0.0, 0.0], [1.5, 0.0, 0.15], [1.5, 0.84, 0.15],
    [0.84, 1.5, 0.15], [0.0, 1.5, 0.15], [1.5, 0.0, 0.075], [1.5, 0.84, 0.075],
    [0.84, 1.5, 0.075], [0.0, 1.5, 0.075], [1.425, 0.0, 0.0], [1.425, 0.798, 0.0],
    [0.798, 1.425, 0.0], [0.0, 1.425, 0.0], [-0.84, 1.5, 0.15], [-1.5, 0.84, 0.15],
    [-1.5, 0.0, 0.15], [-0.84, 1.5, 0.075], [-1.5, 0.84, 0.075], [-1.5, 0.0, 0.075],
    [-0.798, 1.425, 0.0], [-1.425, 0.798, 0.0], [-1.425, 0.0, 0.0], [-1.5, -0.84, 0.15],
    [-0.84, -1.5, 0.15], [0.0, -1.5, 0.15], [-1.5, -0.84, 0.075], [-0.84, -1.5, 0.075],
    [0.0, -1.5, 0.075], [-1.425, -0.798, 0.0], [-0.798, -1.425, 0.0], [0.0, -1.425, 0.0],
    [0.84, -1.5, 0.15], [1.5, -0.84, 0.15], [0.84, -1.5, 0.075], [1.5, -0.84, 0.075],
    [0.798, -1.425, 0.0], [1.425, -0.798, 0.0],
];

/// The 32 bicubic patches as 1-based indices into `TEAPOT_POINTS`, row by
/// row: 28 from Newell's original set plus the 4 later-added bottom patches.
#[rustfmt::skip]
const TEAPOT_PATCHES: [[u16; 16]; 32] = [
    [  1,   2,   3,   4,   5,   6,   7,   8,   9,  10,  11,  12,  13,  14,  15,  16], // rim
    [  4,  17,  18,  19,   8,  20,  21,  22,  12,  23,  24,  25,  16,  26,  27,  28], // rim
    [ 19,  29,  30,  31,  22,  32,  33,  34,  25,  35,  36,  37,  28,  38,  39,  40], // rim
    [ 31,  41,  42,   1,  34,  43,  44,   5,  37,  45,  46,   9,  40,  47,  48,  13], // rim
    [ 13,  14,  15,  16,  49,  50,  51,  52,  53,  54,  55,  56,  57,  58,  59,  60], // upper body
    [ 16,  26,  27,  28,  52,  61,  62,  63,  56,  64,  65,  66,  60,  67,  68,  69], // upper body
    [ 28,  38,  39,  40,  63,  70,  71,  72,  66,  73,  74,  75,  69,  76,  77,  78], // upper body
    [ 40,  47,  48,  13,  72,  79,  80,  49,  75,  81,  82,  53,  78,  83,  84,  57], // upper body
    [ 57,  58,  59,  60,  85,  86,  87,  88,  89,  90,  91,  92,  93,  94,  95,  96], // lower body
    [ 60,  67,  68,  69,  88,  97,  98,  99,  92, 100, 101, 102,  96, 103, 104, 105], // lower body
    [ 69,  76,  77,  78,  99, 106, 107, 108, 102, 109, 110, 111, 105, 112, 113, 114], // lower body
    [ 78,  83,  84,  57, 108, 115, 116,  85, 111, 117, 118,  89, 114, 119, 120,  93], // lower body
    [121, 122, 123, 124, 125, 126, 127, 128, 129, 130, 131, 132, 133, 134, 135, 136], // handle
    [124, 137, 138, 121, 128, 139, 140, 125, 132, 141, 142, 129, 136, 143, 144, 133], // handle
    [133, 134, 135, 136, 145, 146, 147, 148, 149, 150, 151, 152,  69, 153, 154, 155], // handle
    [136, 143, 144, 133, 148, 156, 157, 145, 152, 158, 159, 149, 155, 160, 161,  69], // handle
    [162, 163, 164, 165, 166, 167, 168, 169, 170, 171, 172, 173, 174, 175, 176, 177], // spout
    [165, 178, 179, 162, 169, 180, 181, 166, 173, 182, 183, 170, 177, 184, 185, 174], // spout
    [174, 175, 176, 177, 186, 187, 188, 189, 190, 191, 192, 193, 194, 195, 196, 197], // spout
    [177, 184, 185, 174, 189, 198, 199, 186, 193, 200, 201, 190, 197, 202, 203, 194], // spout
    [204, 204, 204, 204, 207, 208, 209, 210, 211, 211, 211, 211, 212, 213, 214, 215], // lid knob
    [204, 204, 204, 204, 210, 217, 218, 219, 211, 211, 211, 211, 215, 220, 221, 222], // lid knob
    [204, 204, 204, 204, 219, 224, 225, 226, 211, 211, 211, 211, 222, 227, 228, 229], // lid knob
    [204, 204, 204, 204, 226, 230, 231, 207, 211, 211, 211, 211, 229, 232, 233, 212], // lid knob
    [212, 213, 214, 215, 234, 235, 236, 237, 238, 239, 240, 241, 242, 243, 244, 245], // lid
    [215, 220, 221, 222, 237, 246, 247, 248, 241, 249, 250, 251, 245, 252, 253, 254], // lid
    [222, 227, 228, 229, 248, 255, 256, 257, 251, 258, 259, 260, 254, 261, 262, 263], // lid
    [229, 232, 233, 212, 257, 264, 265, 234, 260, 266, 267, 238, 263, 268, 269, 242], // lid
    [270, 270, 270, 270, 279, 280, 281, 282, 275, 276, 277, 278, 271, 272, 273, 274], // bottom
    [270, 270, 270, 270, 282, 289, 290, 291, 278, 286, 287, 288, 274, 283, 284, 285], // bottom
    [270, 270, 270, 270, 291, 298, 299, 300, 288, 295, 296, 297, 285, 292, 293, 294], // bottom
    [270, 270, 270, 270, 300, 305, 306, 279, 297, 303, 304, 275, 294, 301, 302, 271], // bottom
];

#[cfg(test)]
mod tests {
    use super::*;

    /// 6,400 grid triangles minus the 80 lost where patches collapse to a point.
    const TEAPOT_TRIANGLES: usize = 6320;
    /// Bounding box of this tessellation (y up).
    const TEAPOT_LO: V3 = [-3.0, 0.0, -2.0];
    const TEAPOT_HI: V3 = [3.434, 3.15, 2.0];

    const TEAPOT_FINGERPRINT: u64 = 0xE6F6_EDBA_B21E_6056;
    const RANDOM_FINGERPRINT: u64 = 0xE9F3_3D2F_565B_6B0F;
    const THIN_FINGERPRINT: u64 = 0x3BC4_B524_6AE5_F332;
    const CORNELL_FINGERPRINT: u64 = 0x81F2_D253_A6F4_F81E;

    fn scene(name: &str) -> Vec<Tri> {
        builtin_scene(name).expect("known scene")
    }

    fn bbox(tris: &[Tri]) -> (V3, V3) {
        super::super::world_box(tris)
    }

    fn assert_close(actual: V3, expected: V3, tol: f64, what: &str) {
        for k in 0..3 {
            assert!(
                (actual[k] - expected[k]).abs() <= tol,
                "{what}[{k}]: got {}, expected {} +- {tol}",
                actual[k],
                expected[k]
            );
        }
    }

    /// FNV-1a over the bit patterns of all coordinates.
    fn fingerprint(tris: &[Tri]) -> u64 {
        let mut h = 0xCBF2_9CE4_8422_2325_u64;
        for c in tris.iter().flatten().flatten() {
            for byte in c.to_bits().to_le_bytes() {
                h = (h ^ u64::from(byte)).wrapping_mul(0x0100_0000_01B3);
            }
        }
        h
    }

    #[test]
    fn names_and_descriptions_match() {
        assert_eq!(BUILTIN_NAMES.len(), BUILTIN_DESCRIPTIONS.len());
        for name in BUILTIN_NAMES {
            assert!(!scene(name).is_empty(), "{name} is empty");
        }
        assert!(builtin_scene("no-such-scene").is_none());
        assert!(builtin_scene("").is_none());
        assert!(builtin_scene("Teapot").is_none());
    }

    #[test]
    fn all_triangles_finite_and_non_degenerate() {
        for name in BUILTIN_NAMES {
            for (i, t) in scene(name).iter().enumerate() {
                assert!(t.iter().flatten().all(|c| c.is_finite()), "{name} #{i}: {t:?}");
                assert!(!is_degenerate(t), "{name} #{i} is degenerate: {t:?}");
            }
        }
    }

    #[test]
    fn scenes_are_bit_identical_across_calls() {
        for name in BUILTIN_NAMES {
            let (a, b) = (scene(name), scene(name));
            assert_eq!(a.len(), b.len(), "{name}");
            let bits = |s: &[Tri]| s.iter().flatten().flatten().map(|c| c.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&a), bits(&b), "{name}");
        }
    }

    /// Pins the exact output of the scenes computed with +, -, *, / and sqrt
    /// only (IEEE-exact everywhere). If a deliberate change breaks this,
    /// update the constants: reference renders of these scenes change too.
    #[test]
    fn scene_fingerprints_are_stable() {
        assert_eq!(fingerprint(&scene("teapot")), TEAPOT_FINGERPRINT);
        assert_eq!(fingerprint(&scene("random")), RANDOM_FINGERPRINT);
        assert_eq!(fingerprint(&scene("thin")), THIN_FINGERPRINT);
        assert_eq!(fingerprint(&scene("cornell")), CORNELL_FINGERPRINT);
    }

    #[test]
    fn teapot_data_is_well_formed() {
        let used = TEAPOT_PATCHES.iter().flatten();
        assert!(used.clone().all(|&i| (1..=306).contains(&i)));
        // Only the four near-duplicates of the lid-knob apex are unused.
        let mut unused: Vec<usize> = (1..=306).collect();
        unused.retain(|&i| !used.clone().any(|&j| usize::from(j) == i));
        assert_eq!(unused, [205, 206, 216, 223]);
    }

    /// Catches transcription errors: the revolved parts come in groups of four
    /// patches, each a quarter turn of the previous; handle and spout come in
    /// pairs mirrored in y (with the rows reversed).
    #[test]
    fn teapot_data_has_its_symmetries() {
        // The bottom faces down, so its patches turn the other way round.
        for (first, sign) in [(0, 1.0), (4, 1.0), (8, 1.0), (20, 1.0), (24, 1.0), (28, -1.0)] {
            for k in 1..4 {
                let prev = teapot_patch(&TEAPOT_PATCHES[first + k - 1]);
                let turned = prev.map(|[x, y, z]| [sign * y, -sign * x, z]);
                assert_eq!(teapot_patch(&TEAPOT_PATCHES[first + k]), turned, "patch {}", first + k);
            }
        }
        for first in [12, 14, 16, 18] {
            let a = teapot_patch(&TEAPOT_PATCHES[first]);
            let mirrored: [V3; 16] = from_fn(|i| {
                let [x, y, z] = a[4 * (i / 4) + 3 - i % 4];
                [x, -y, z]
            });
            assert_eq!(teapot_patch(&TEAPOT_PATCHES[first + 1]), mirrored, "patch {}", first + 1);
        }
    }

    #[test]
    fn teapot_count_and_extents() {
        let tris = scene("teapot");
        assert_eq!(tris.len(), TEAPOT_TRIANGLES);
        let (lo, hi) = bbox(&tris);
        // Exact values of this tessellation ...
        assert_close(lo, TEAPOT_LO, 1e-6, "teapot min");
        assert_close(hi, TEAPOT_HI, 1e-6, "teapot max");
        // ... and the teapot's known extents: handle to spout tip, standing on
        // y = 0 with the lid knob at 3.15, body radius 2.
        assert_close(lo, [-3.0, 0.0, -2.0], 0.01, "teapot min");
        assert_close(hi, [3.434, 3.15, 2.0], 0.01, "teapot max");
    }

    /// Patches that meet share bit-identical edge vertices, so the only edges
    /// used by a single triangle are the 16 open patch edges x 10 quads: the
    /// rim top, the lid's lower edge and the two ends of handle and spout.
    #[test]
    fn teapot_patches_join_without_cracks() {
        let mut edges = std::collections::HashMap::<[[u64; 3]; 2], usize>::new();
        for t in scene("teapot") {
            for i in 0..3 {
                let mut e = [t[i], t[(i + 1) % 3]].map(|v| v.map(f64::to_bits));
                e.sort();
                *edges.entry(e).or_default() += 1;
            }
        }
        assert!(edges.values().all(|&c| c <= 2));
        assert_eq!(edges.values().filter(|&&c| c == 1).count(), 16 * TEAPOT_K);
    }

    #[test]
    fn jackstraws_shape() {
        let tris = scene("jackstraws");
        assert_eq!(tris.len(), STICKS * 2 * STICK_SEGMENTS);
        assert_eq!(tris.len(), 12 * 2048);
        let (lo, hi) = bbox(&tris);
        let r = STICK_RADIUS + 1e-12;
        assert!(lo.iter().all(|&c| c >= -1.0 - r) && hi.iter().all(|&c| c <= 1.0 + r));
        // Every triangle is a long, narrow sliver along its stick.
        for t in &tris {
            let lengths = [sub(t[1], t[0]), sub(t[2], t[1]), sub(t[0], t[2])]
                .map(|e| (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]).sqrt());
            let longest = lengths.iter().cloned().fold(0.0, f64::max);
            let shortest = lengths.iter().cloned().fold(f64::INFINITY, f64::min);
            assert!((longest - 2.0).abs() < 1e-3 && shortest < 1e-4, "{lengths:?}");
        }
    }

    #[test]
    fn thin_sliver_spans_the_scene_box() {
        let tris = scene("thin");
        assert_eq!(tris.len(), 5);
        let frame = bbox(&tris[..4]);
        assert_eq!(frame, ([0.0; 3], [1.0; 3]));
        let sliver = tris[4];
        assert_eq!(bbox(&[sliver]), frame);
        let n = cross(sub(sliver[1], sliver[0]), sub(sliver[2], sliver[0]));
        let area = 0.5 * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        assert!(area > 1e-4 && area < 1e-2, "sliver area {area}");
    }

    #[test]
    fn random_shape() {
        let tris = scene("random");
        assert_eq!(tris.len(), RANDOM_TRIANGLES);
        let (lo, hi) = bbox(&tris);
        assert!(lo.iter().all(|&c| c >= -0.1) && hi.iter().all(|&c| c <= 1.1));
        assert_close(lo, [-0.05; 3], 0.05, "random min");
        assert_close(hi, [1.05; 3], 0.05, "random max");
    }

    #[test]
    fn cornell_extents() {
        let tris = scene("cornell");
        assert_eq!(tris.len(), 32);
        let (lo, hi) = bbox(&tris);
        assert_close(lo, [0.0; 3], 0.5, "cornell min");
        assert_close(hi, [556.0, 548.8, 559.2], 0.5, "cornell max");
        // Triangles 4 and 5 are the light.
        assert!(tris[4..6].iter().flatten().all(|v| v[1] == 548.8));
        assert_eq!(bbox(&tris[4..6]), ([213.0, 548.8, 227.0], [343.0, 548.8, 332.0]));
    }
}

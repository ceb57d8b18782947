//! Float references: the same BIH (converted back to world space) and the same kind of
//! triangle test in f64 or f32, or pbrt's watertight test in f32. They measure the golden
//! model; they are not meant to be fast.
//!
//! The tree is the golden model's, with every clip plane moved outwards by one grid unit:
//! world vertices may lie up to half a unit outside their rounded grid positions, so the
//! float traversal never culls a triangle the float test would hit. Triangles that are
//! degenerate on the grid (absent from the tree) but not in float are tested on every ray.

use super::float::{FloatTri, Real, watertight_f32};
use crate::scene::Scene;
use crate::scene::bih::{Node, Step, inner_step};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FloatTest {
    /// Hanika's accelerated Badouel/Wald test in the scene's float type.
    Wald,
    /// pbrt's watertight test (f32 only).
    Watertight,
}

#[derive(Clone, Copy, Debug)]
enum FNode<F> {
    Inner { axis: u8, clip0: F, clip1: F, child: u32 },
    Leaf { first: u32, count: u32 },
}

pub struct FloatScene<F: Real> {
    tris: Vec<Option<FloatTri<F>>>,
    verts32: Vec<[[f32; 3]; 3]>,
    nodes: Vec<FNode<F>>,
    /// Input triangle numbers, leaf by leaf.
    leaf_ids: Vec<u32>,
    /// Input triangles missing from the tree that the float test can still hit.
    extra: Vec<u32>,
    box_lo: [F; 3],
    box_hi: [F; 3],
    test: FloatTest,
}

impl<F: Real> FloatScene<F> {
    pub fn new(scene: &Scene, test: FloatTest) -> Self {
        let tf = scene.transform;
        let unit = 1.0 / tf.scale;
        let world = |k: usize, g: f64| F::from_f64(g * unit + tf.min[k]);
        let tris: Vec<Option<FloatTri<F>>> =
            scene.world.iter().map(|t| FloatTri::new(t.map(|v| v.map(F::from_f64)))).collect();
        let verts32 = scene.world.iter().map(|t| t.map(|v| v.map(|x| x as f32))).collect();
        let nodes = scene
            .bih
            .nodes
            .iter()
            .map(|n| match *n {
                Node::Inner { axis, clip0, clip1, child } => {
                    let a = axis as usize;
                    FNode::Inner {
                        axis,
                        clip0: world(a, clip0 as f64 + 1.0),
                        clip1: world(a, clip1 as f64 - 1.0),
                        child,
                    }
                }
                Node::Leaf { first, count } => FNode::Leaf { first, count },
            })
            .collect();
        let leaf_ids = scene.bih.leaf_tris.iter().map(|&i| scene.tri_ids[i as usize]).collect();
        let mut in_tree = vec![false; scene.world.len()];
        for &id in &scene.tri_ids {
            in_tree[id as usize] = true;
        }
        let hittable = |i: usize| match test {
            FloatTest::Wald => tris[i].is_some(),
            FloatTest::Watertight => true,
        };
        let extra = (0..scene.world.len()).filter(|&i| !in_tree[i] && hittable(i)).map(|i| i as u32).collect();
        let box_lo = std::array::from_fn(|k| world(k, -1.0));
        let box_hi = std::array::from_fn(|k| world(k, scene.grid_box.hi[k] as f64 + 1.0));
        FloatScene { tris, verts32, nodes, leaf_ids, extra, box_lo, box_hi, test }
    }

    fn test_tri(&self, id: u32, o: [F; 3], d: [F; 3], t_max: F) -> Option<F> {
        match self.test {
            FloatTest::Wald => self.tris[id as usize]?.intersect(o, d, F::zero(), t_max).map(|h| h.0),
            FloatTest::Watertight => {
                let o32 = o.map(|x| x.to_f64() as f32);
                let d32 = d.map(|x| x.to_f64() as f32);
                watertight_f32(o32, d32, self.verts32[id as usize], t_max.to_f64() as f32)
                    .map(|h| F::from_f64(h.0 as f64))
            }
        }
    }

    /// Closest hit as (input triangle number, t along `d`); ties go to the smaller number.
    pub fn trace(&self, o: [F; 3], d: [F; 3]) -> Option<(u32, F)> {
        let mut best: Option<(u32, F)> = None;
        let consider = |id: u32, best: &mut Option<(u32, F)>| {
            let t_max = best.map_or(F::max_value(), |b| b.1);
            // t_max is inclusive for the tie-break, so test against a slightly larger bound.
            if let Some(t) =
                self.test_tri(id, o, d, if best.is_some() { t_max + t_max.abs() * F::from_f64(1e-12) } else { t_max })
                && best.is_none_or(|b| t < b.1 || (t == b.1 && id < b.0))
            {
                *best = Some((id, t));
            }
        };
        for &id in &self.extra {
            consider(id, &mut best);
        }
        let inv = super::float::inv_dir(d);
        let Some((t0, t1)) = super::float::ray_box(o, inv, self.box_lo, self.box_hi, F::zero(), F::max_value()) else {
            return best;
        };
        let mut stack: Vec<(u32, F, F)> = Vec::with_capacity(64);
        let (mut node, mut tmin, mut tmax) = (0u32, t0, t1);
        loop {
            let mut pop = false;
            match self.nodes[node as usize] {
                FNode::Inner { axis, clip0, clip1, child } => {
                    let a = axis as usize;
                    if d[a] == F::zero() {
                        // Parallel to the planes: a child is entered iff the origin lies in it.
                        let left = o[a] <= clip0;
                        let right = o[a] >= clip1;
                        match (left, right) {
                            (true, true) => {
                                stack.push((child + 1, tmin, tmax));
                                node = child;
                            }
                            (true, false) => node = child,
                            (false, true) => node = child + 1,
                            (false, false) => pop = true,
                        }
                    } else {
                        let d0 = (clip0 - o[a]) * inv[a];
                        let d1 = (clip1 - o[a]) * inv[a];
                        match inner_step(child, d[a] > F::zero(), d0, d1, tmin, tmax) {
                            Step::Both { near, near_max, far, far_min } => {
                                stack.push((far, far_min, tmax));
                                (node, tmax) = (near, near_max);
                            }
                            Step::Near(near, near_max) => (node, tmax) = (near, near_max),
                            Step::Far(far, far_min) => (node, tmin) = (far, far_min),
                            Step::Neither => pop = true,
                        }
                    }
                }
                FNode::Leaf { first, count } => {
                    for &id in &self.leaf_ids[first as usize..(first + count) as usize] {
                        consider(id, &mut best);
                    }
                    pop = true;
                }
            }
            if pop {
                match stack.pop() {
                    Some(s) => (node, tmin, tmax) = s,
                    None => return best,
                }
            }
        }
    }
}

//! Bounding interval hierarchy (Wächter & Keller 2006) built with integer arithmetic only:
//! halving an integer box and comparing doubled centroids, so the build is exact and
//! deterministic. The depth is bounded by the hardware stack (seed 001 §3.4).

use serde::Serialize;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Node {
    /// Children are `child` (left, bounded above by clip0) and `child + 1` (right, bounded
    /// below by clip1) along `axis`.
    Inner { axis: u8, clip0: i64, clip1: i64, child: u32 },
    /// `count` entries of the leaf table starting at `first`.
    Leaf { first: u32, count: u32 },
}

/// What traversal does at an inner node (seed 001 table 3.1: inner → node, push or pop).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Step<T> {
    /// Enter `near` with tmax = `near_max`; push (`far`, `far_min`, old tmax).
    Both {
        near: u32,
        near_max: T,
        far: u32,
        far_min: T,
    },
    /// Enter only the near child, with tmax lowered to the second field.
    Near(u32, T),
    /// Enter only the far child, with tmin raised to the second field.
    Far(u32, T),
    Neither,
}

/// The child decision shared by the golden model and the float references: with the ray
/// going up the axis (`positive`) the left child (ending at d0 = distance to clip0) is near,
/// otherwise the right one (ending at d1). `T` is i64 in the golden model, f32/f64 in the
/// references.
#[inline(always)]
pub fn inner_step<T: PartialOrd + Copy>(child: u32, positive: bool, d0: T, d1: T, tmin: T, tmax: T) -> Step<T> {
    let (near, far, near_end, far_start) =
        if positive { (child, child + 1, d0, d1) } else { (child + 1, child, d1, d0) };
    let near_max = if near_end < tmax { near_end } else { tmax };
    let far_min = if far_start > tmin { far_start } else { tmin };
    match (tmin <= near_max, far_min <= tmax) {
        (true, true) => Step::Both { near, near_max, far, far_min },
        (true, false) => Step::Near(near, near_max),
        (false, true) => Step::Far(far, far_min),
        (false, false) => Step::Neither,
    }
}

/// Integer axis-aligned box, inclusive bounds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct IBox {
    pub lo: [i64; 3],
    pub hi: [i64; 3],
}

impl IBox {
    pub fn of_points(points: &[[i64; 3]]) -> IBox {
        let mut b = IBox { lo: [i64::MAX; 3], hi: [i64::MIN; 3] };
        for p in points {
            for k in 0..3 {
                b.lo[k] = b.lo[k].min(p[k]);
                b.hi[k] = b.hi[k].max(p[k]);
            }
        }
        b
    }
    fn longest_axis(&self) -> usize {
        let ext: [i64; 3] = std::array::from_fn(|k| self.hi[k] - self.lo[k]);
        (0..3).fold(0, |best, k| if ext[k] > ext[best] { k } else { best })
    }
}

#[derive(Clone, Debug, Default, Serialize)]
pub struct Bih {
    pub nodes: Vec<Node>,
    /// Triangle numbers (indices into the triangle table), leaf by leaf.
    pub leaf_tris: Vec<u32>,
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct BihStats {
    pub nodes: usize,
    pub inner: usize,
    pub leaves: usize,
    pub empty_leaves: usize,
    /// Inner nodes on the longest root-to-leaf path: the stack entries traversal may need.
    pub depth: usize,
    pub max_leaf_size: usize,
    pub mean_leaf_size: f64,
    /// Leaves larger than --leaf-size (forced by the depth bound or identical centroids).
    pub oversized_leaves: usize,
}

struct Builder<'a> {
    bounds: &'a [IBox],
    leaf_size: usize,
    max_depth: usize,
    bih: Bih,
    stats: BihStats,
}

/// Builds the hierarchy over triangles with the given integer bounding boxes. `scene` is the
/// box the first split halves; `max_depth` bounds the inner nodes on any path.
pub fn build(bounds: &[IBox], scene: IBox, leaf_size: usize, max_depth: usize) -> (Bih, BihStats) {
    let mut b = Builder { bounds, leaf_size, max_depth, bih: Bih::default(), stats: BihStats::default() };
    let mut ids: Vec<u32> = (0..bounds.len() as u32).collect();
    b.bih.nodes.push(Node::Leaf { first: 0, count: 0 });
    b.node(0, &mut ids, scene, 0);
    let mut stats = b.stats;
    stats.nodes = b.bih.nodes.len();
    stats.mean_leaf_size = if stats.leaves > 0 { b.bih.leaf_tris.len() as f64 / stats.leaves as f64 } else { 0.0 };
    (b.bih, stats)
}

impl Builder<'_> {
    fn leaf(&mut self, at: usize, ids: &mut [u32]) {
        ids.sort_unstable();
        let first = self.bih.leaf_tris.len() as u32;
        self.bih.leaf_tris.extend_from_slice(ids);
        self.bih.nodes[at] = Node::Leaf { first, count: ids.len() as u32 };
        self.stats.leaves += 1;
        self.stats.empty_leaves += ids.is_empty() as usize;
        self.stats.max_leaf_size = self.stats.max_leaf_size.max(ids.len());
        self.stats.oversized_leaves += (ids.len() > self.leaf_size) as usize;
    }

    fn node(&mut self, at: usize, ids: &mut [u32], mut split_box: IBox, depth: usize) {
        self.stats.depth = self.stats.depth.max(depth);
        if ids.len() <= self.leaf_size || depth >= self.max_depth {
            return self.leaf(at, ids);
        }
        loop {
            let axis = split_box.longest_axis();
            let (lo, hi) = (split_box.lo[axis], split_box.hi[axis]);
            if lo >= hi {
                // The split box has shrunk to a point: nothing left to separate.
                return self.leaf(at, ids);
            }
            let mid = (lo + hi) >> 1;
            // Left iff the centroid lies at or below mid + 1/2 (doubled to stay integer);
            // the halves [lo, mid] and [mid+1, hi] both shrink, so the loop ends.
            let is_left = |t: &u32| {
                let b = &self.bounds[*t as usize];
                b.lo[axis] + b.hi[axis] <= 2 * mid + 1
            };
            let n_left = partition(ids, is_left);
            let (mut left_box, mut right_box) = (split_box, split_box);
            left_box.hi[axis] = mid;
            right_box.lo[axis] = mid + 1;
            if n_left == 0 {
                split_box = right_box;
                continue;
            }
            if n_left == ids.len() {
                split_box = left_box;
                continue;
            }
            let (left, right) = ids.split_at_mut(n_left);
            let clip0 = left.iter().map(|&t| self.bounds[t as usize].hi[axis]).max().unwrap_or(lo);
            let clip1 = right.iter().map(|&t| self.bounds[t as usize].lo[axis]).min().unwrap_or(hi);
            let child = self.bih.nodes.len();
            self.bih.nodes.push(Node::Leaf { first: 0, count: 0 });
            self.bih.nodes.push(Node::Leaf { first: 0, count: 0 });
            self.bih.nodes[at] = Node::Inner { axis: axis as u8, clip0, clip1, child: child as u32 };
            self.stats.inner += 1;
            self.node(child, left, left_box, depth + 1);
            self.node(child + 1, right, right_box, depth + 1);
            return;
        }
    }
}

/// Stable in-place partition; returns the number of elements for which `pred` holds.
fn partition(ids: &mut [u32], pred: impl Fn(&u32) -> bool) -> usize {
    let (yes, no): (Vec<u32>, Vec<u32>) = ids.iter().partition(|t| pred(t));
    let n = yes.len();
    ids[..n].copy_from_slice(&yes);
    ids[n..].copy_from_slice(&no);
    n
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Collects (triangles under node, inner-node depth of each leaf) and checks clip planes.
    fn check(
        bih: &Bih,
        bounds: &[IBox],
        at: usize,
        depth: usize,
        seen: &mut Vec<u32>,
        max_depth: &mut usize,
    ) -> Vec<u32> {
        match bih.nodes[at] {
            Node::Leaf { first, count } => {
                *max_depth = (*max_depth).max(depth);
                let t = bih.leaf_tris[first as usize..(first + count) as usize].to_vec();
                seen.extend(&t);
                t
            }
            Node::Inner { axis, clip0, clip1, child } => {
                let l = check(bih, bounds, child as usize, depth + 1, seen, max_depth);
                let r = check(bih, bounds, child as usize + 1, depth + 1, seen, max_depth);
                for &t in &l {
                    assert!(bounds[t as usize].hi[axis as usize] <= clip0, "left child beyond clip0");
                }
                for &t in &r {
                    assert!(bounds[t as usize].lo[axis as usize] >= clip1, "right child beyond clip1");
                }
                [l, r].concat()
            }
        }
    }

    proptest! {
        #[test]
        fn invariants(boxes in prop::collection::vec((0i64..1000, 0i64..1000, 0i64..1000, 0i64..60, 0i64..60, 0i64..60), 1..300),
                      leaf_size in 1usize..6, max_depth in 1usize..12) {
            let bounds: Vec<IBox> = boxes.iter().map(|&(x, y, z, a, b, c)| IBox { lo: [x, y, z], hi: [x + a, y + b, z + c] }).collect();
            let scene = IBox { lo: [0; 3], hi: [1060; 3] };
            let (bih, stats) = build(&bounds, scene, leaf_size, max_depth);
            let (mut seen, mut depth) = (Vec::new(), 0);
            check(&bih, &bounds, 0, 0, &mut seen, &mut depth);
            seen.sort_unstable();
            // Every triangle is reachable, exactly once.
            prop_assert_eq!(seen, (0..bounds.len() as u32).collect::<Vec<_>>());
            prop_assert!(depth <= max_depth);
            prop_assert_eq!(depth, stats.depth);
            prop_assert_eq!(stats.nodes, bih.nodes.len());
        }
    }

    #[test]
    fn identical_triangles_end_in_one_leaf() {
        let bounds = vec![IBox { lo: [5; 3], hi: [9; 3] }; 20];
        let (bih, stats) = build(&bounds, IBox { lo: [0; 3], hi: [100; 3] }, 4, 32);
        assert_eq!(bih.nodes.len(), 1);
        assert_eq!(stats.max_leaf_size, 20);
        assert_eq!(stats.oversized_leaves, 1);
    }
}

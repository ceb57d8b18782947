//! Bounding interval hierarchy (Wächter & Keller 2006) built with integer arithmetic only, so
//! the build is exact and deterministic. Two ways to choose an inner node's split (`--tree`):
//! the thesis's middle split, halving an integer box and comparing doubled centroids, and a
//! binned surface-area heuristic over the same doubled centroids with integer areas
//! (docs/ARITHMETIC.md §5, DECISIONS.md 11 and 72). The depth is bounded by the hardware
//! stack (seed 001 §3.4).

use serde::Serialize;

/// How the builder chooses an inner node's split plane: the `--tree` parameter.
use crate::params::TreeSplit as Split;

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
    /// Half the surface area, xy + yz + zx with the extents hi − lo, exact (extents are
    /// below 2^42, so the sum is below 2^86).
    pub fn half_area(&self) -> u128 {
        let e: [u128; 3] = std::array::from_fn(|k| (self.hi[k] - self.lo[k]).max(0) as u128);
        e[0] * e[1] + e[1] * e[2] + e[2] * e[0]
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
    split: Split,
    /// `Params::sah_step_percent`: 0, or the SAH's price of a node step in hundredths of a
    /// triangle test, by which nodes within the leaf size are split further.
    step_percent: u32,
    bih: Bih,
    stats: BihStats,
}

/// Bins per axis of the SAH build.
pub const SAH_BINS: usize = 32;

/// Builds the hierarchy over triangles with the given integer bounding boxes. `scene` is the
/// box the first split halves (the root's box, which holds every triangle); `max_depth`
/// bounds the inner nodes on any path. With the SAH and a `step_percent` (0: none), a node
/// within `leaf_size` is split further while the SAH prices the split below the leaf
/// (`Builder::split_pays`).
pub fn build(
    bounds: &[IBox],
    scene: IBox,
    leaf_size: usize,
    max_depth: usize,
    split: Split,
    step_percent: u32,
) -> (Bih, BihStats) {
    let mut b =
        Builder { bounds, leaf_size, max_depth, split, step_percent, bih: Bih::default(), stats: BihStats::default() };
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

    fn node(&mut self, at: usize, ids: &mut [u32], split_box: IBox, depth: usize) {
        self.stats.depth = self.stats.depth.max(depth);
        let within = ids.len() <= self.leaf_size;
        if depth >= self.max_depth || (within && (self.split == Split::Middle || self.step_percent == 0)) {
            return self.leaf(at, ids);
        }
        match self.split {
            Split::Middle => self.middle(at, ids, split_box, depth),
            Split::Sah => match sah_split(self.bounds, ids, &split_box) {
                Some(s) if !within || self.split_pays(&s, ids.len(), &split_box) => {
                    self.sah(at, ids, s, split_box, depth)
                }
                // Every centroid is the same point (no plane separates them), or the node is
                // within the leaf size and its best split does not pay.
                _ => self.leaf(at, ids),
            },
        }
    }

    /// Whether the SAH prices `s`, the best split of a node of `count` triangles within the
    /// leaf size, below the leaf: with the node step costing `step_percent` hundredths of a
    /// triangle test, a leaf costs A · count tests and the split A · step + s.cost (A the
    /// node box's half-area; s.cost the children's Σ half-area · count), in exact u128.
    fn split_pays(&self, s: &SahSplit, count: usize, node_box: &IBox) -> bool {
        let a = node_box.half_area();
        a * self.step_percent as u128 + 100 * s.cost < 100 * a * count as u128
    }

    /// Turns `at` into an inner node over `ids`, whose first `n_left` go left, and builds
    /// the children with the boxes `child_boxes` makes of (clip0, clip1).
    fn inner(
        &mut self,
        at: usize,
        ids: &mut [u32],
        n_left: usize,
        axis: usize,
        depth: usize,
        child_boxes: impl Fn(i64, i64) -> (IBox, IBox),
    ) {
        let (left, right) = ids.split_at_mut(n_left);
        let clip0 = left.iter().map(|&t| self.bounds[t as usize].hi[axis]).max().expect("left is not empty");
        let clip1 = right.iter().map(|&t| self.bounds[t as usize].lo[axis]).min().expect("right is not empty");
        let (left_box, right_box) = child_boxes(clip0, clip1);
        let child = self.bih.nodes.len();
        self.bih.nodes.push(Node::Leaf { first: 0, count: 0 });
        self.bih.nodes.push(Node::Leaf { first: 0, count: 0 });
        self.bih.nodes[at] = Node::Inner { axis: axis as u8, clip0, clip1, child: child as u32 };
        self.stats.inner += 1;
        self.node(child, left, left_box, depth + 1);
        self.node(child + 1, right, right_box, depth + 1);
    }

    /// The thesis's middle split (DECISIONS.md 11).
    fn middle(&mut self, at: usize, ids: &mut [u32], mut split_box: IBox, depth: usize) {
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
            // The children's split boxes are the halves, whatever the clip planes.
            return self.inner(at, ids, n_left, axis, depth, |_, _| (left_box, right_box));
        }
    }

    /// The binned SAH split (DECISIONS.md 72, docs/ARITHMETIC.md §5). `node_box` is the box
    /// traversal confines the node's rays to: the scene box clipped by the planes of every
    /// ancestor, so it holds all of `ids`.
    fn sah(&mut self, at: usize, ids: &mut [u32], s: SahSplit, node_box: IBox, depth: usize) {
        let n_left = partition(ids, |t| s.goes_left(&self.bounds[*t as usize]));
        debug_assert_eq!(n_left, s.n_left);
        let axis = s.axis;
        self.inner(at, ids, n_left, axis, depth, |clip0, clip1| {
            let (mut l, mut r) = (node_box, node_box);
            l.hi[axis] = clip0;
            r.lo[axis] = clip1;
            (l, r)
        })
    }
}

/// The chosen SAH split of one node: the triangles whose doubled centroid on `axis` falls in
/// a bin below `bin` go left.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct SahSplit {
    axis: usize,
    /// Smallest doubled centroid and the span (largest − smallest + 1) the bins divide.
    cmin: i64,
    span: i64,
    bin: usize,
    n_left: usize,
    /// Σ half-area(child box) · triangles of that child.
    cost: u128,
}

impl SahSplit {
    fn bin_of(cmin: i64, span: i64, c2: i64) -> usize {
        ((c2 - cmin) as i128 * SAH_BINS as i128 / span as i128) as usize
    }
    fn goes_left(&self, b: &IBox) -> bool {
        Self::bin_of(self.cmin, self.span, b.lo[self.axis] + b.hi[self.axis]) < self.bin
    }
}

/// The best binned SAH split of `ids` inside `node_box`, or None when every doubled centroid
/// is the same point. On each axis whose centroids differ, the doubled centroids
/// c = lo + hi are put into SAH_BINS equal bins over [min c, max c]; each of the
/// SAH_BINS − 1 bin boundaries with triangles on both sides is a candidate, whose left child
/// box is `node_box` with hi = clip0 (the left triangles' largest hi) on the axis and right
/// child box `node_box` with lo = clip1 (the right triangles' smallest lo). Its cost is
/// half-area(left box) · left count + half-area(right box) · right count, exact in u128; the
/// smallest cost wins, ties going to the lower axis, then the lower boundary.
fn sah_split(bounds: &[IBox], ids: &[u32], node_box: &IBox) -> Option<SahSplit> {
    #[derive(Clone, Copy)]
    struct Bin {
        count: usize,
        max_hi: i64,
        min_lo: i64,
    }
    let empty = Bin { count: 0, max_hi: i64::MIN, min_lo: i64::MAX };
    let mut best: Option<SahSplit> = None;
    for axis in 0..3 {
        let c2 = |t: u32| bounds[t as usize].lo[axis] + bounds[t as usize].hi[axis];
        let cmin = ids.iter().map(|&t| c2(t)).min()?;
        let cmax = ids.iter().map(|&t| c2(t)).max()?;
        if cmin == cmax {
            continue;
        }
        let span = cmax - cmin + 1;
        let mut bins = [empty; SAH_BINS];
        for &t in ids {
            let b = &mut bins[SahSplit::bin_of(cmin, span, c2(t))];
            b.count += 1;
            b.max_hi = b.max_hi.max(bounds[t as usize].hi[axis]);
            b.min_lo = b.min_lo.min(bounds[t as usize].lo[axis]);
        }
        // Right sides, from the top: right[i] = bins i.. together.
        let mut right = [empty; SAH_BINS + 1];
        for i in (0..SAH_BINS).rev() {
            right[i] = Bin {
                count: right[i + 1].count + bins[i].count,
                max_hi: i64::MIN,
                min_lo: right[i + 1].min_lo.min(bins[i].min_lo),
            };
        }
        let mut left = empty;
        for bin in 1..SAH_BINS {
            let b = bins[bin - 1];
            left = Bin { count: left.count + b.count, max_hi: left.max_hi.max(b.max_hi), min_lo: i64::MAX };
            let r = right[bin];
            if left.count == 0 || r.count == 0 {
                continue;
            }
            let (mut lb, mut rb) = (*node_box, *node_box);
            lb.hi[axis] = left.max_hi;
            rb.lo[axis] = r.min_lo;
            let cost = lb.half_area() * left.count as u128 + rb.half_area() * r.count as u128;
            if best.is_none_or(|b| cost < b.cost) {
                best = Some(SahSplit { axis, cmin, span, bin, n_left: left.count, cost });
            }
        }
    }
    best
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

    /// Every triangle reachable exactly once, inside its clip planes (`check`), the depth bound
    /// kept and counted: the tree's depth.
    fn walkable(bih: &Bih, stats: &BihStats, bounds: &[IBox], max_depth: usize) -> Result<usize, TestCaseError> {
        let (mut seen, mut depth) = (Vec::new(), 0);
        check(bih, bounds, 0, 0, &mut seen, &mut depth);
        seen.sort_unstable();
        prop_assert_eq!(seen, (0..bounds.len() as u32).collect::<Vec<_>>());
        prop_assert!(depth <= max_depth);
        prop_assert_eq!(depth, stats.depth);
        prop_assert_eq!(stats.nodes, bih.nodes.len());
        Ok(depth)
    }

    proptest! {
        #[test]
        fn invariants(boxes in prop::collection::vec((0i64..1000, 0i64..1000, 0i64..1000, 0i64..60, 0i64..60, 0i64..60), 1..300),
                      leaf_size in 1usize..6, max_depth in 1usize..12, split in prop::sample::select(Split::ALL.to_vec())) {
            let bounds: Vec<IBox> = boxes.iter().map(|&(x, y, z, a, b, c)| IBox { lo: [x, y, z], hi: [x + a, y + b, z + c] }).collect();
            let scene = IBox { lo: [0; 3], hi: [1060; 3] };
            let (bih, stats) = build(&bounds, scene, leaf_size, max_depth, split, 0);
            walkable(&bih, &stats, &bounds, max_depth)?;
        }
    }

    proptest! {
        /// SAH on larger, clustered inputs: every triangle reachable once, every triangle
        /// inside its clip planes (`check`), the depth bound kept, and leaves above leaf_size
        /// only where the depth bound or identical centroids force them.
        #[test]
        fn sah_invariants(clusters in prop::collection::vec((0i64..4000, 0i64..4000, 0i64..4000), 1..6),
                          boxes in prop::collection::vec((0usize..6, 0i64..300, 0i64..300, 0i64..300, 0i64..200, 0i64..200, 0i64..200), 1..600),
                          leaf_size in 1usize..9, max_depth in 1usize..24) {
            let bounds: Vec<IBox> = boxes.iter().map(|&(c, x, y, z, a, b, d)| {
                let o = clusters[c % clusters.len()];
                IBox { lo: [o.0 + x, o.1 + y, o.2 + z], hi: [o.0 + x + a, o.1 + y + b, o.2 + z + d] }
            }).collect();
            let scene = IBox { lo: [0; 3], hi: [4500; 3] };
            let (bih, stats) = build(&bounds, scene, leaf_size, max_depth, Split::Sah, 0);
            let depth = walkable(&bih, &stats, &bounds, max_depth)?;
            prop_assert_eq!(stats.inner + stats.leaves, stats.nodes);
            if depth < max_depth {
                let centroids_differ = |tris: &[u32]| tris.iter().any(|&t| {
                    (0..3).any(|k| bounds[t as usize].lo[k] + bounds[t as usize].hi[k] != bounds[tris[0] as usize].lo[k] + bounds[tris[0] as usize].hi[k])
                });
                for n in &bih.nodes {
                    if let Node::Leaf { first, count } = *n {
                        let tris = &bih.leaf_tris[first as usize..(first + count) as usize];
                        prop_assert!(tris.len() <= leaf_size || !centroids_differ(tris), "oversized leaf {:?}", tris);
                    }
                }
            }
            // Deterministic: the same input builds the same tree.
            let again = build(&bounds, scene, leaf_size, max_depth, Split::Sah, 0).0;
            prop_assert_eq!(again.nodes, bih.nodes);
            prop_assert_eq!(again.leaf_tris, bih.leaf_tris);
        }
    }

    /// Two clusters at the ends of a long box: SAH cuts the empty space between them at the
    /// root, where the middle split's halves leave one cluster's box reaching across it.
    #[test]
    fn sah_separates_clusters() {
        let mut bounds = Vec::new();
        for i in 0..8 {
            bounds.push(IBox { lo: [i, 0, 0], hi: [i + 10, 10, 10] });
            bounds.push(IBox { lo: [600 + i, 0, 0], hi: [610 + i, 10, 10] });
        }
        let scene = IBox { lo: [0; 3], hi: [1000, 10, 10] };
        let (bih, _) = build(&bounds, scene, 8, 32, Split::Sah, 0);
        assert_eq!(bih.nodes[0], Node::Inner { axis: 0, clip0: 17, clip1: 600, child: 1 });
        assert_eq!(bih.nodes[1], Node::Leaf { first: 0, count: 8 });
        assert_eq!(bih.leaf_tris[..8], [0, 2, 4, 6, 8, 10, 12, 14]);
    }

    /// Boxes a, b, c along x in a 100 × 10 × 10 node.
    const THREE_BOXES: [IBox; 3] = [
        IBox { lo: [0, 0, 0], hi: [10, 10, 10] },
        IBox { lo: [5, 0, 0], hi: [20, 10, 10] },
        IBox { lo: [90, 0, 0], hi: [100, 10, 10] },
    ];

    /// The cost of a candidate is Σ half-area(child box) · count, the child boxes being the
    /// node box clipped at clip0 and clip1 on the split axis; the cheapest wins.
    #[test]
    fn sah_cost_is_clipped_area_times_count() {
        // Three unit-ish boxes along x in a 100 × 10 × 10 node: {a, b} | {c} is the best cut.
        let bounds = THREE_BOXES;
        let node = IBox { lo: [0; 3], hi: [100, 10, 10] };
        let s = sah_split(&bounds, &[0, 1, 2], &node).unwrap();
        assert_eq!((s.axis, s.n_left), (0, 2));
        // Left box [0, 20] × 10 × 10: 20·10 + 10·10 + 10·20 = 500; right [90, 100]: 300.
        assert_eq!(s.cost, 500 * 2 + 300);
        assert_eq!(IBox { lo: [0; 3], hi: [20, 10, 10] }.half_area(), 500);
        // All centroids equal: no split.
        assert_eq!(sah_split(&[bounds[0]; 3], &[0, 1, 2], &node), None);
    }

    /// With a node-step price the SAH splits a node within the leaf size exactly when
    /// A · step + cost < A · count. The three boxes above: A = 2100, the best split's cost
    /// 1300, three triangles: it pays below 5000 / 21 = 238.1 % (then the pair {a, b}, whose
    /// split would cost 500 · 2.38 + 700 against 1000, stays a leaf); without a price, or at
    /// 239 %, the node is one leaf; the middle split has no price.
    #[test]
    fn a_priced_node_step_splits_a_node_within_the_leaf_size_where_the_sah_says_it_pays() {
        let bounds = THREE_BOXES;
        let node = IBox { lo: [0; 3], hi: [100, 10, 10] };
        let nodes = |split, step| build(&bounds, node, 4, 32, split, step).0.nodes;
        assert_eq!(nodes(Split::Sah, 0).len(), 1);
        assert_eq!(nodes(Split::Sah, 239).len(), 1);
        let priced = nodes(Split::Sah, 238);
        assert_eq!(priced[0], Node::Inner { axis: 0, clip0: 20, clip1: 90, child: 1 });
        assert_eq!(priced[1..], [Node::Leaf { first: 0, count: 2 }, Node::Leaf { first: 2, count: 1 }]);
        assert_eq!(nodes(Split::Middle, 238).len(), 1);
    }

    #[test]
    fn identical_triangles_end_in_one_leaf() {
        let bounds = vec![IBox { lo: [5; 3], hi: [9; 3] }; 20];
        for split in Split::ALL {
            let (bih, stats) = build(&bounds, IBox { lo: [0; 3], hi: [100; 3] }, 4, 32, split, 0);
            assert_eq!(bih.nodes.len(), 1);
            assert_eq!(stats.max_leaf_size, 20);
            assert_eq!(stats.oversized_leaves, 1);
        }
    }
}

//! A traversal unit's widths and parameters (`TraverseParams`), and reading fields of the
//! scene's ROM words.

use super::brom::read_cycles;
use super::clock::ClockTarget;
use super::mul::MulStyle;
use crate::rtl::Ty;
use crate::rtl::build::S;
use crate::scene::images::SceneRoms;
use crate::scene::rom::{self, Field, Layout, Word, rom_addr_bits};

/// The widths of one traversal unit.
#[derive(Clone, Debug)]
pub struct TraverseParams {
    pub n: u32,
    pub m: u32,
    pub c: u32,
    pub id_width: u32,
    pub stack_depth: u32,
    pub box_hi: [i64; 3],
    pub tri_bits: u32,
    /// How the plane-distance product is built (`plane::plane_product`): the clock target's.
    pub product: MulStyle,
    /// Whether the plane distances and the leaves pushed get a landing register by their
    /// users (targets from `clock::LANDING_FROM_MHZ`).
    pub landing: bool,
    /// Whether the unit is a spread core's (`clock::spread`), with the registers such a core
    /// gets across the die.
    pub spread: bool,
    /// Clocks of a node ROM read and of a leaf ROM read (`brom::read_cycles`: 3 for block RAM,
    /// whose fabric register the placer puts between the blocks spread over the die and the
    /// logic; 2 for LUTs). The emitted triangle stream is `leaf_rom_cycles` behind `leaf`.
    pub node_rom_cycles: u32,
    pub leaf_rom_cycles: u32,
    /// Ray slots of the unit: rays it holds at once, each with its own registers and stack.
    pub slots: u32,
    /// The scene's tag (`SceneRoms::tag`), in the names of the modules built for the scene.
    pub scene_tag: String,
    /// The node word the unit reads (the node ROM's, or the scene image's node record), the
    /// bits of a node's number and of a leaf's `first`, and the root's number.
    pub node_layout: Layout,
    pub node_bits: u32,
    pub leaf_bits: u32,
    pub root: u64,
    /// Whether the nodes come through a cache (`with_node_cache`): a lookup in C + 1 answered in
    /// N, a miss parked in the retry queue.
    pub node_cache: bool,
    /// With `Some`: a parent's step sends its near child to the leaf queue itself when that
    /// child is a leaf with entries (DECISIONS 137), from the pair ROM (`pair_image`): the
    /// unit sends `pair_addr` a clock after N and gets `pair_word` this many clocks later.
    pub pair_rom_cycles: Option<u32>,
}

impl TraverseParams {
    pub fn new(scene: &SceneRoms, id_width: u32, target: ClockTarget, slots: u32) -> TraverseParams {
        let p = &scene.params;
        TraverseParams {
            n: p.n,
            m: p.m,
            c: p.c,
            id_width,
            stack_depth: p.stack_depth,
            box_hi: scene.box_hi,
            tri_bits: rom::addr_bits(scene.tri_count()),
            product: target.mul_style(),
            landing: target.splits(super::clock::LANDING_FROM_MHZ),
            spread: false,
            node_rom_cycles: read_cycles(scene.node.1.len()),
            leaf_rom_cycles: read_cycles(scene.leaf.1.len()),
            slots,
            scene_tag: scene.tag(),
            node_layout: scene.node.0.clone(),
            node_bits: rom_addr_bits(scene.node.1.len()),
            leaf_bits: rom_addr_bits(scene.leaf.1.len()),
            root: 0,
            node_cache: false,
            pair_rom_cycles: None,
        }
    }

    /// This unit with leaves sent by their parents (`pair_rom_cycles`), where the scene's
    /// node table allows it (`pair_image`).
    pub fn sending_leaves(mut self, scene: &SceneRoms) -> TraverseParams {
        self.pair_rom_cycles = pair_rom_words(scene).map(read_cycles);
        self
    }

    /// Bits of a leaf's (first, count) in a pair word.
    pub fn leaf_fields_bits(&self) -> u32 {
        leaf_fields_bits(self.leaf_bits, &self.node_layout)
    }

    /// The unit of an external-memory core: node records of the scene image (`layout`), read
    /// through a node cache: the lookup one clock after C (once the cull test is known, so a
    /// culled entry fetches nothing), its answer `cache::LATENCY` clocks later in N.
    pub fn with_node_cache(mut self, layout: &crate::scene::memory::MemoryLayout) -> TraverseParams {
        self.node_layout = layout.node.clone();
        self.node_bits = crate::bits::addr_bits(layout.node_records as usize);
        self.leaf_bits = layout.node.field("first").width;
        self.root = crate::scene::memory::ROOT_RECORD;
        self.node_rom_cycles = 1 + super::cache::LATENCY;
        self.node_cache = true;
        // The pair ROM would hold the whole tree's leaves on chip.
        self.pair_rom_cycles = None;
        self
    }
    /// Reciprocal directions: m + C bits.
    pub fn inv_width(&self) -> u32 {
        self.m + self.c
    }
    /// The widths of the unit's ray RAMs: the origins' (3n), then each axis's reciprocal
    /// direction.
    pub fn ray_ram_widths(&self) -> [u32; 4] {
        [3 * self.n, self.inv_width(), self.inv_width(), self.inv_width()]
    }
    /// LUT-RAM groups of the unit's ray RAMs (`wide_ram`): each written from a write enable
    /// and a slot register of its own (the ports `ray_we_gI`, `ray_slot_gI`).
    pub fn ray_ram_groups(&self) -> usize {
        self.ray_ram_widths().iter().map(|&w| super::wide_ram::group_widths(w).len()).sum()
    }
    /// Distances: −1 … 2^(n+1), signed n + 3 bits.
    pub fn dist_ty(&self) -> Ty {
        Ty::s(self.n + 3)
    }
    /// Leaf entry distances are never negative: unsigned n + 2 bits.
    pub fn tmin_width(&self) -> u32 {
        self.n + 2
    }
    /// Bits of a slot number within the unit.
    pub fn slot_bits(&self) -> u32 {
        rom::rom_addr_bits(self.slots as usize)
    }
    pub fn sp_width(&self) -> u32 {
        rom::value_bits(self.stack_depth as usize)
    }
}

/// Bits of a leaf's (first, count) in a pair word: `first`'s `leaf_bits` (the leaf table's
/// address bits) above the node word's `count`.
fn leaf_fields_bits(leaf_bits: u32, node_layout: &Layout) -> u32 {
    leaf_bits + node_layout.field("count").width
}

/// The pair ROM of a scene's node table: word i holds, for the children 2i + 1 (low half) and
/// 2i + 2 (high half), each child's leaf fields `first` (the leaf table's address bits) above
/// `count`, or 0 when the child is not a leaf with entries. Word i answers the inner nodes
/// whose `child` is 2i + 1: every inner node's, as `scene::bih` numbers them (the root 0, then
/// the children in pairs). None for a node table numbered otherwise (a folder's ROMs), and for
/// a tree without inner nodes.
pub fn pair_image(scene: &SceneRoms) -> Option<Vec<u128>> {
    let words = pair_rom_words(scene)?;
    let (layout, nodes) = (&scene.node.0, &scene.node.1);
    let f = |name: &str| layout.field(name);
    let (first, count) = (f("first"), f("count"));
    let fields_bits = leaf_fields_bits(rom_addr_bits(scene.leaf.1.len()), layout);
    let leaf_fields = |w: &Word| -> u128 {
        let n = word_bits(w, count.lsb, count.width);
        if is_leaf(layout, w) && n != 0 { word_bits(w, first.lsb, first.width) << count.width | n } else { 0 }
    };
    let at = |k: usize| nodes.get(k).map_or(0, leaf_fields);
    Some((0..words).map(|i| at(2 * i + 2) << fields_bits | at(2 * i + 1)).collect())
}

/// The pair ROM's words where the node table allows one (`pair_image`): every inner node's
/// child odd, three nodes at least (a tree of one leaf has no parent to send it), and a pair
/// word within 128 bits.
fn pair_rom_words(scene: &SceneRoms) -> Option<usize> {
    let (layout, nodes) = (&scene.node.0, &scene.node.1);
    let child = layout.field("child");
    let fields_bits = leaf_fields_bits(rom_addr_bits(scene.leaf.1.len()), layout);
    let children_odd =
        nodes.iter().filter(|w| !is_leaf(layout, w)).all(|w| word_bits(w, child.lsb, child.width) % 2 == 1);
    (nodes.len() >= 3 && children_odd && 2 * fields_bits <= 128).then(|| nodes.len().div_ceil(2))
}

/// Whether a node word is a leaf (axis 3).
fn is_leaf(layout: &Layout, w: &Word) -> bool {
    let axis = layout.field("axis");
    word_bits(w, axis.lsb, axis.width) == 3
}

/// Bits [lsb, lsb + width) of a ROM word (width ≤ 128).
pub fn word_bits(w: &Word, lsb: u32, width: u32) -> u128 {
    (0..width).fold(0u128, |acc, b| {
        let bit = lsb + b;
        acc | ((((w.0[(bit / 64) as usize] >> (bit % 64)) & 1) as u128) << b)
    })
}

/// A field of a ROM read: its bits as a signal of the field's type.
pub fn field<'b>(name: &str, word: S<'b>, f: &Field, word_lsb: u32) -> S<'b> {
    let raw = word.slice(f.lsb - word_lsb, f.width);
    if f.signed { raw.signed().name(name) } else { raw.name(name) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::Params;
    use crate::scene::bih::Node;
    use crate::scene::{Scene, SceneSource};

    /// Each pair word holds its two children's leaf fields (a leaf with entries) or 0, as the
    /// scene's tree has them; a node table whose inner nodes do not name odd children (a
    /// folder's ROMs numbered otherwise) gets no pair ROM.
    #[test]
    fn a_pair_word_holds_its_children_leaf_fields() {
        let scene = Scene::load(&SceneSource::Builtin("teapot".into()), &Params::default()).unwrap();
        let mut roms = SceneRoms::of(&scene);
        let image = pair_image(&roms).expect("the tree's children are numbered in pairs");
        let p = TraverseParams::new(&roms, 16, ClockTarget(150), 4).sending_leaves(&roms);
        let count_bits = roms.node.0.field("count").width;
        let fields_bits = p.leaf_fields_bits();
        let mut sent = 0;
        for (k, node) in scene.bih.nodes.iter().enumerate().skip(1) {
            let (word, half) = (image[(k - 1) / 2], (k - 1) % 2);
            let got = word >> (half as u32 * fields_bits) & ((1 << fields_bits) - 1);
            let want = match *node {
                Node::Leaf { first, count } if count > 0 => (first as u128) << count_bits | count as u128,
                _ => 0,
            };
            assert_eq!(got, want, "node {k}");
            sent += (want != 0) as usize;
        }
        assert!(sent > 1000, "{sent} leaves");
        let child = roms.node.0.field("child").clone();
        let inner = roms.node.1.iter_mut().find(|w| w.get(roms.node.0.field("axis")) != 3).unwrap();
        inner.0[(child.lsb / 64) as usize] ^= 1 << (child.lsb % 64);
        assert!(pair_image(&roms).is_none());
    }
}

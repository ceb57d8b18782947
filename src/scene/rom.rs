//! ROM images of a scene: the triangle table, the BIH node table and the leaf table, each as
//! `$readmemh` text (.hex and .mem), a Xilinx .coe file, and one VHDL package holding all
//! three. The bit layout of every word is in docs/ROM-LAYOUT.md and in `layouts()`.

use super::Scene;
use super::bih::Node;
use serde::Serialize;
use std::fmt::Write as _;

/// One field of a ROM word: bits [lsb, lsb + width).
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Field {
    pub name: &'static str,
    pub lsb: u32,
    pub width: u32,
    pub signed: bool,
}

#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Layout {
    pub rom: &'static str,
    pub width: u32,
    pub depth: usize,
    pub fields: Vec<Field>,
}

impl Layout {
    pub(super) fn build(rom: &'static str, depth: usize, spec: &[(&'static str, u32, bool)]) -> Layout {
        let mut lsb = 0;
        let fields = spec
            .iter()
            .map(|&(name, width, signed)| {
                let f = Field { name, lsb, width, signed };
                lsb += width;
                f
            })
            .collect();
        Layout { rom, width: lsb, depth, fields }
    }
    pub fn field(&self, name: &str) -> &Field {
        self.fields.iter().find(|f| f.name == name).expect("field exists")
    }
}

pub use crate::bits::{addr_bits, rom_addr_bits, rom_depth, value_bits};

/// The three layouts for a scene; widths depend on n, m and the scene's table sizes.
pub fn layouts(scene: &Scene) -> [Layout; 3] {
    let max_count = scene
        .bih
        .nodes
        .iter()
        .map(|x| if let Node::Leaf { count, .. } = x { *count as usize } else { 0 })
        .max()
        .unwrap_or(0);
    layouts_for(
        scene.params.n,
        scene.params.m,
        scene.tris.len(),
        scene.bih.nodes.len(),
        scene.bih.leaf_tris.len().max(1),
        value_bits(max_count),
    )
}

/// The layouts for `tris` triangles, `nodes` BIH nodes and `leaf_entries` leaf-table words,
/// with `count_bits` bits for a leaf's triangle count.
pub fn layouts_for(n: u32, m: u32, tris: usize, nodes: usize, leaf_entries: usize, count_bits: u32) -> [Layout; 3] {
    let tri = Layout::build(
        "tri",
        tris,
        &[
            ("r", 2, false),
            ("pp", n, false),
            ("pq", n, false),
            ("d", n + 3, true),
            ("np", m, true),
            ("nq", m, true),
            ("e1p", m, true),
            ("e1q", m, true),
            ("e2p", m, true),
            ("e2q", m, true),
        ],
    );
    let node_bits = addr_bits(nodes);
    let leaf_bits = addr_bits(leaf_entries);
    // Inner and leaf nodes share one word; the leaf fields overlay clip0/clip1/child.
    let inner_bits = 2 * n + node_bits;
    let leaf_fields = leaf_bits + count_bits;
    let pad = inner_bits.max(leaf_fields);
    let mut node = Layout::build(
        "node",
        nodes,
        &[("axis", 2, false), ("clip0", n, false), ("clip1", n, false), ("child", node_bits, false)],
    );
    node.fields.push(Field { name: "first", lsb: 2, width: leaf_bits, signed: false });
    node.fields.push(Field { name: "count", lsb: 2 + leaf_bits, width: count_bits, signed: false });
    node.width = 2 + pad;
    let leaf = Layout::build("leaf", leaf_entries, &[("tri", addr_bits(tris), false)]);
    [tri, node, leaf]
}

/// A wide word as little-endian 64-bit limbs.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Word(pub Vec<u64>);

impl Word {
    pub(super) fn zero(width: u32) -> Word {
        Word(vec![0; width.div_ceil(64) as usize])
    }
    /// Stores `value` (two's complement for negatives) in bits [lsb, lsb + width).
    pub(super) fn set(&mut self, f: &Field, value: i128) {
        let lim_ok = if f.signed {
            value >= -(1i128 << (f.width - 1)) && value < (1i128 << (f.width - 1))
        } else {
            value >= 0 && (f.width >= 127 || value < (1i128 << f.width))
        };
        assert!(lim_ok, "value {value} does not fit ROM field {} ({} bits)", f.name, f.width);
        for b in 0..f.width {
            if (value >> b.min(127)) & 1 == 1 {
                let bit = f.lsb + b;
                self.0[(bit / 64) as usize] |= 1u64 << (bit % 64);
            }
        }
    }
    pub fn get(&self, f: &Field) -> i128 {
        let mut v: i128 = 0;
        for b in 0..f.width {
            let bit = f.lsb + b;
            v |= (((self.0[(bit / 64) as usize] >> (bit % 64)) & 1) as i128) << b;
        }
        if f.signed && (v >> (f.width - 1)) & 1 == 1 { v - (1i128 << f.width) } else { v }
    }
    /// The word of hex digits `s` (most significant first), as `hex` writes it.
    pub fn from_hex(s: &str) -> Option<Word> {
        let mut w = Word(vec![0; (4 * s.len()).div_ceil(64).max(1)]);
        for (k, c) in s.chars().rev().enumerate() {
            let nib = c.to_digit(16)? as u64;
            w.0[k / 16] |= nib << (4 * (k % 16));
        }
        Some(w)
    }
    /// Hex digits, most significant first, exactly ceil(width / 4) of them.
    pub fn hex(&self, width: u32) -> String {
        let digits = width.div_ceil(4);
        (0..digits)
            .rev()
            .map(|d| {
                let bit = d * 4;
                let nib = (self.0[(bit / 64) as usize] >> (bit % 64)) & 0xF;
                char::from_digit(nib as u32, 16).unwrap_or('0')
            })
            .collect()
    }
}

/// The words of all three ROMs.
pub fn words(scene: &Scene) -> [(Layout, Vec<Word>); 3] {
    let [tri_l, node_l, leaf_l] = layouts(scene);
    let tris = scene
        .tris
        .iter()
        .map(|t| {
            let mut w = Word::zero(tri_l.width);
            for (name, v) in [
                ("r", t.r as i64),
                ("pp", t.pp),
                ("pq", t.pq),
                ("d", t.d),
                ("np", t.np),
                ("nq", t.nq),
                ("e1p", t.e1p),
                ("e1q", t.e1q),
                ("e2p", t.e2p),
                ("e2q", t.e2q),
            ] {
                w.set(tri_l.field(name), v as i128);
            }
            w
        })
        .collect();
    let nodes = scene
        .bih
        .nodes
        .iter()
        .map(|nd| {
            let mut w = Word::zero(node_l.width);
            match *nd {
                Node::Inner { axis, clip0, clip1, child } => {
                    for (name, v) in [
                        ("axis", axis as i128),
                        ("clip0", clip0 as i128),
                        ("clip1", clip1 as i128),
                        ("child", child as i128),
                    ] {
                        w.set(node_l.field(name), v);
                    }
                }
                Node::Leaf { first, count } => {
                    for (name, v) in [("axis", 3), ("first", first as i128), ("count", count as i128)] {
                        w.set(node_l.field(name), v);
                    }
                }
            }
            w
        })
        .collect();
    let mut leaves: Vec<Word> = scene
        .bih
        .leaf_tris
        .iter()
        .map(|&t| {
            let mut w = Word::zero(leaf_l.width);
            w.set(leaf_l.field("tri"), t as i128);
            w
        })
        .collect();
    if leaves.is_empty() {
        leaves.push(Word::zero(leaf_l.width));
    }
    [(tri_l, tris), (node_l, nodes), (leaf_l, leaves)]
}

pub fn readmemh(layout: &Layout, words: &[Word]) -> String {
    let mut s =
        format!("// fxrt {} ROM: {} words of {} bits, see docs/ROM-LAYOUT.md\n", layout.rom, words.len(), layout.width);
    for w in words {
        s.push_str(&w.hex(layout.width));
        s.push('\n');
    }
    s
}

pub fn coe(layout: &Layout, words: &[Word]) -> String {
    let mut s = format!(
        "; fxrt {} ROM: {} words of {} bits\nmemory_initialization_radix=16;\nmemory_initialization_vector=\n",
        layout.rom,
        words.len(),
        layout.width
    );
    for (i, w) in words.iter().enumerate() {
        let end = if i + 1 == words.len() { ";" } else { "," };
        let _ = writeln!(s, "{}{end}", w.hex(layout.width));
    }
    s
}

/// A VHDL-93 package with the three ROMs as constant arrays plus every field position.
/// Words are written as bit strings, so any width is exact (x"…" needs multiples of 4).
pub fn vhdl_package(scene: &Scene, roms: &[(Layout, Vec<Word>)]) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "-- fxrt scene ROMs for '{}' (n={}, m={}, E={}); generated, do not edit.",
        scene.name, scene.params.n, scene.params.m, scene.edge_shift
    );
    s.push_str("library ieee;\nuse ieee.std_logic_1164.all;\n\npackage fxrt_scene_pkg is\n");
    for (l, words) in roms {
        let up = l.rom.to_uppercase();
        let _ = writeln!(s, "  constant {up}_WIDTH : natural := {};", l.width);
        let _ = writeln!(s, "  constant {up}_DEPTH : natural := {};", words.len());
        for f in &l.fields {
            let _ = writeln!(s, "  constant {up}_{}_LSB : natural := {};", f.name.to_uppercase(), f.lsb);
            let _ = writeln!(s, "  constant {up}_{}_WIDTH : natural := {};", f.name.to_uppercase(), f.width);
        }
        let _ = writeln!(
            s,
            "  type {}_rom_t is array (0 to {}) of std_logic_vector({} downto 0);",
            l.rom,
            words.len() - 1,
            l.width - 1
        );
        let _ = writeln!(s, "  constant {up}_ROM : {}_rom_t := (", l.rom);
        for (i, w) in words.iter().enumerate() {
            let bits: String = (0..l.width)
                .rev()
                .map(|b| if (w.0[(b / 64) as usize] >> (b % 64)) & 1 == 1 { '1' } else { '0' })
                .collect();
            let end = if i + 1 == words.len() { "" } else { "," };
            let _ = writeln!(s, "    {i} => \"{bits}\"{end}");
        }
        s.push_str("  );\n");
    }
    s.push_str("end package fxrt_scene_pkg;\n");
    s
}

#[cfg(test)]
mod tests {
    /// A one-word memory still has a one-bit address, so it is built with two words.
    #[test]
    fn every_address_is_a_word() {
        for words in [1usize, 2, 3, 4, 5, 1000] {
            assert_eq!(super::rom_depth(words), 1 << super::rom_addr_bits(words), "{words}");
            assert!(super::rom_depth(words) >= words);
        }
    }

    use super::*;
    use crate::params::Params;

    #[test]
    fn fields_round_trip_through_words() {
        let tris = crate::scene::builtin::builtin_scene("random").unwrap();
        let s = Scene::build("random", tris, &Params { n: 23, m: 27, ..Params::default() }).unwrap();
        let [(tl, tw), (nl, nw), (ll, lw)] = words(&s);
        for (t, w) in s.tris.iter().zip(&tw) {
            assert_eq!(w.get(tl.field("d")), t.d as i128);
            assert_eq!(w.get(tl.field("e2q")), t.e2q as i128);
            assert_eq!(w.get(tl.field("r")), t.r as i128);
        }
        for (nd, w) in s.bih.nodes.iter().zip(&nw) {
            match *nd {
                Node::Inner { axis, clip1, child, .. } => {
                    assert_eq!(w.get(nl.field("axis")), axis as i128);
                    assert_eq!(w.get(nl.field("clip1")), clip1 as i128);
                    assert_eq!(w.get(nl.field("child")), child as i128);
                }
                Node::Leaf { first, count } => {
                    assert_eq!(w.get(nl.field("axis")), 3);
                    assert_eq!(w.get(nl.field("first")), first as i128);
                    assert_eq!(w.get(nl.field("count")), count as i128);
                }
            }
        }
        assert_eq!(lw.len(), s.bih.leaf_tris.len());
        assert_eq!(lw[3].get(ll.field("tri")), s.bih.leaf_tris[3] as i128);
        assert_eq!(tl.width, 2 + 3 * 23 + 3 + 6 * 27);
    }

    #[test]
    fn hex_has_exact_digit_count() {
        let l = Layout::build("x", 1, &[("a", 5, true), ("b", 3, false)]);
        let mut w = Word::zero(l.width);
        w.set(l.field("a"), -1);
        w.set(l.field("b"), 5);
        assert_eq!(w.hex(l.width), "bf");
        assert_eq!(w.get(l.field("a")), -1);
    }
}

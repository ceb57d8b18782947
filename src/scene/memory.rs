//! The scene image for external memory (`scene.bin`, docs/MEMORY.md): the BIH nodes and the
//! triangles at addresses chosen for the core's caches, built from the ROM images and read back
//! into them. Nodes are 2^k-byte records with every child pair in one aligned block; triangles
//! are stored leaf by leaf (the leaf table is gone: a leaf points at its first triangle record),
//! as many whole records to a cache line as fit, each record carrying its triangle number.

use super::images::SceneRoms;
use super::rom::{Field, Layout, Word};
use crate::bits::{addr_bits, value_bits};
use crate::error::{Error, Result};
use serde::Serialize;
use std::path::Path;

/// The first eight bytes of every scene image.
pub const MAGIC: &[u8; 8] = b"FXRTSCN1";
/// Bytes of the header (its fields in `Header`); the node region starts at the first line
/// boundary at or after it.
pub const HEADER_BYTES: usize = 64;
/// Memory data widths the AXI read port supports (`--mem-bits`).
pub const MEM_BITS: [u32; 3] = [32, 64, 128];
/// The default `--mem-bits` and `--cache-line` (bytes); the line was chosen with
/// `examples/memory_study.rs` (docs/MEMORY.md).
pub const DEFAULT_MEM_BITS: u32 = 64;
pub const DEFAULT_LINE_BYTES: u32 = 128;

/// What the image's addresses are built for: the memory's data width and the cache line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct MemoryShape {
    pub mem_bits: u32,
    pub line_bytes: u32,
}

impl Default for MemoryShape {
    fn default() -> Self {
        MemoryShape { mem_bits: DEFAULT_MEM_BITS, line_bytes: DEFAULT_LINE_BYTES }
    }
}

impl MemoryShape {
    /// Bytes one beat of the read port carries.
    pub fn beat_bytes(&self) -> u32 {
        self.mem_bits / 8
    }

    /// A line is one AXI4 burst: a power of two (so no burst crosses a 4 KB boundary), at
    /// least two beats, at most 256 beats and 4 KB.
    pub fn validate(&self) -> std::result::Result<(), (&'static str, String)> {
        if !MEM_BITS.contains(&self.mem_bits) {
            return Err(("mem-bits", format!("{} is not one of 32, 64, 128", self.mem_bits)));
        }
        let (line, beat) = (self.line_bytes, self.beat_bytes());
        if !line.is_power_of_two() || line < 2 * beat || line > 4096 || line / beat > 256 {
            return Err((
                "cache-line",
                format!(
                    "{line} bytes: a line must be a power of two from {} to 4096 bytes (two beats of {} bits up to 4 KB)",
                    2 * beat,
                    self.mem_bits
                ),
            ));
        }
        Ok(())
    }
}

/// Where everything is in the image, and the bit layout of its records.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct MemoryLayout {
    pub shape: MemoryShape,
    /// Bytes of a node record: a power of two, at least one beat.
    pub node_bytes: u32,
    /// Bytes of a triangle record: whole beats.
    pub tri_bytes: u32,
    /// Triangle records in one line (the rest of a line is zero).
    pub tris_per_line: u32,
    /// Low bits of a triangle pointer that number the record in its line; the bits above
    /// number the line in the triangle region.
    pub slot_bits: u32,
    /// Byte offset of node record 0; record k is at `node_offset + k * node_bytes`.
    pub node_offset: u64,
    /// Node records: the ROM's nodes moved up by one (record 0 is zero), so the root is
    /// record 1 and every child pair (2i + 2, 2i + 3) lies in one aligned block.
    pub node_records: u64,
    /// Byte offset of triangle line 0; pointer (line, slot) is at
    /// `tri_offset + line * line_bytes + slot * tri_bytes`.
    pub tri_offset: u64,
    pub tri_records: u64,
    pub tri_lines: u64,
    /// Bytes of the whole image (a multiple of the line).
    pub total_bytes: u64,
    /// The node record: the ROM node's fields, `child` a record number, `first` a pointer.
    pub node: Layout,
    /// The triangle record: the ROM triangle's fields and `id`, its triangle number.
    pub tri: Layout,
}

/// The root's node record.
pub const ROOT_RECORD: u64 = 1;

impl MemoryLayout {
    pub fn for_roms(roms: &SceneRoms, shape: MemoryShape) -> Result<MemoryLayout> {
        shape.validate().map_err(|(p, m)| Error::param(p, m))?;
        let (n, line) = (roms.params.n, shape.line_bytes as u64);
        let beat = shape.beat_bytes();
        let records = roms.leaf.1.len() as u64;
        let mut tri = roms.tri.0.clone();
        tri.rom = "tri_record";
        let id = Field { name: "id", lsb: tri.width, width: addr_bits(roms.tri_count()), signed: false };
        tri.width += id.width;
        tri.fields.push(id);
        let tri_bytes = tri.width.div_ceil(8 * beat) * beat;
        let tris_per_line = shape.line_bytes / tri_bytes;
        if tris_per_line == 0 {
            return Err(Error::param(
                "cache-line",
                format!("{line} bytes hold no triangle record of {tri_bytes} bytes; take a longer line"),
            ));
        }
        let slot_bits = if tris_per_line == 1 { 0 } else { addr_bits(tris_per_line as usize) };
        let tri_lines = records.div_ceil(tris_per_line as u64).max(1);
        let node_records = roms.node.1.len() as u64 + 1;
        let count_bits = roms.node.0.field("count").width;
        let pointer_bits = addr_bits(tri_lines as usize) + slot_bits;
        let node = node_layout(n, addr_bits(node_records as usize), pointer_bits, count_bits);
        let node_bytes = node.width.div_ceil(8).next_power_of_two().max(beat);
        if 2 * node_bytes as u64 > line {
            return Err(Error::param(
                "cache-line",
                format!("{line} bytes hold no child pair of {node_bytes}-byte node records; take a longer line"),
            ));
        }
        let node_offset = (HEADER_BYTES as u64).next_multiple_of(line);
        let tri_offset = (node_offset + node_records * node_bytes as u64).next_multiple_of(line);
        let total_bytes = tri_offset + tri_lines * line;
        Ok(MemoryLayout {
            shape,
            node_bytes,
            tri_bytes,
            tris_per_line,
            slot_bits,
            node_offset,
            node_records,
            tri_offset,
            tri_records: records,
            tri_lines,
            total_bytes,
            node,
            tri,
        })
    }

    /// The pointer a leaf stores for triangle record `k` (records numbered leaf by leaf).
    pub fn pointer(&self, k: u64) -> u64 {
        let per = self.tris_per_line as u64;
        ((k / per) << self.slot_bits) | (k % per)
    }

    /// A pointer's (line, slot).
    pub fn split(&self, pointer: u64) -> (u64, u64) {
        (pointer >> self.slot_bits, pointer & ((1 << self.slot_bits) - 1))
    }

    /// The pointer of the record after the one `pointer` names (the hardware's increment: the
    /// slot counts up to `tris_per_line`, then the line moves on).
    pub fn next(&self, pointer: u64) -> u64 {
        let (line, slot) = self.split(pointer);
        if slot + 1 == self.tris_per_line as u64 { (line + 1) << self.slot_bits } else { pointer + 1 }
    }

    /// Byte address (from the image's base) of the record a pointer names.
    pub fn tri_address(&self, pointer: u64) -> u64 {
        let (line, slot) = self.split(pointer);
        self.tri_offset + line * self.shape.line_bytes as u64 + slot * self.tri_bytes as u64
    }

    pub fn node_address(&self, record: u64) -> u64 {
        self.node_offset + record * self.node_bytes as u64
    }

    /// Bits of a byte address into the image.
    pub fn address_bits(&self) -> u32 {
        value_bits(self.total_bytes.saturating_sub(1) as usize)
    }
}

/// The node record's fields: the ROM node's, with `child` a record number of `child_bits` and
/// `first` a triangle pointer of `pointer_bits` (leaf fields overlay clip0 as in the ROM).
fn node_layout(n: u32, child_bits: u32, pointer_bits: u32, count_bits: u32) -> Layout {
    let mut node = Layout::build(
        "node_record",
        0,
        &[("axis", 2, false), ("clip0", n, false), ("clip1", n, false), ("child", child_bits, false)],
    );
    node.fields.push(Field { name: "first", lsb: 2, width: pointer_bits, signed: false });
    node.fields.push(Field { name: "count", lsb: 2 + pointer_bits, width: count_bits, signed: false });
    node.width = 2 + (2 * n + child_bits).max(pointer_bits + count_bits);
    node
}

/// A scene image: its layout and bytes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SceneImage {
    pub layout: MemoryLayout,
    pub bytes: Vec<u8>,
}

/// The header's fields, little-endian after the magic: u32 version, n, m, edge shift, mem
/// bits, line bytes, node bytes, tri bytes, tris per line, slot bits; u64 node records, tri
/// records (the rest of the 64 bytes zero). Enough to find every record without scene.json.
const HEADER_U32: usize = 10;

impl SceneImage {
    pub fn build(roms: &SceneRoms, shape: MemoryShape) -> Result<SceneImage> {
        let l = MemoryLayout::for_roms(roms, shape)?;
        let mut bytes = vec![0u8; l.total_bytes as usize];
        bytes[..8].copy_from_slice(MAGIC);
        let p = &roms.params;
        let head = [1, p.n, p.m, roms.edge_shift, shape.mem_bits, shape.line_bytes, l.node_bytes, l.tri_bytes];
        let head = head.into_iter().chain([l.tris_per_line, l.slot_bits]);
        for (k, v) in head.enumerate() {
            bytes[8 + 4 * k..12 + 4 * k].copy_from_slice(&v.to_le_bytes());
        }
        let at = 8 + 4 * HEADER_U32;
        bytes[at..at + 8].copy_from_slice(&l.node_records.to_le_bytes());
        bytes[at + 8..at + 16].copy_from_slice(&l.tri_records.to_le_bytes());
        let (rom_node, rom_tri) = (&roms.node.0, &roms.tri.0);
        for (i, w) in roms.node.1.iter().enumerate() {
            let mut rec = Word::zero(l.node.width);
            let axis = w.get(rom_node.field("axis"));
            rec.set(l.node.field("axis"), axis);
            if axis == 3 {
                let first = w.get(rom_node.field("first")) as u64;
                rec.set(l.node.field("first"), l.pointer(first) as i128);
                rec.set(l.node.field("count"), w.get(rom_node.field("count")));
            } else {
                for f in ["clip0", "clip1"] {
                    rec.set(l.node.field(f), w.get(rom_node.field(f)));
                }
                rec.set(l.node.field("child"), w.get(rom_node.field("child")) + 1);
            }
            put(&mut bytes, l.node_address(i as u64 + 1), l.node_bytes, &rec);
        }
        let id = l.tri.field("id").clone();
        for (k, entry) in roms.leaf.1.iter().enumerate().take(l.tri_records as usize) {
            let t = entry.get(roms.leaf.0.field("tri"));
            let mut rec = roms.tri.1[t as usize].clone();
            rec.0.resize(l.tri.width.div_ceil(64) as usize, 0);
            rec.set(&id, t);
            debug_assert_eq!(rom_tri.width, id.lsb);
            put(&mut bytes, l.tri_address(l.pointer(k as u64)), l.tri_bytes, &rec);
        }
        Ok(SceneImage { layout: l, bytes })
    }

    /// The node record `record` as a word of `layout.node`.
    pub fn node(&self, record: u64) -> Word {
        get(&self.bytes, self.layout.node_address(record), self.layout.node_bytes)
    }

    /// The triangle record a pointer names.
    pub fn tri(&self, pointer: u64) -> Word {
        get(&self.bytes, self.layout.tri_address(pointer), self.layout.tri_bytes)
    }

    /// The ROM images this image was built from, rebuilt from its bytes alone (with the ROM
    /// layouts `roms` gives): nodes moved back down, leaf pointers turned into leaf-table
    /// entries, triangles put back at their numbers. `SceneImage::build` then this is identity.
    pub fn to_rom_words(&self, rom: &SceneRoms) -> (Vec<Word>, Vec<Word>, Vec<Word>) {
        let l = &self.layout;
        let (node_l, tri_l, leaf_l) = (&rom.node.0, &rom.tri.0, &rom.leaf.0);
        let nodes = (1..l.node_records)
            .map(|k| {
                let rec = self.node(k);
                let mut w = Word::zero(node_l.width);
                let axis = rec.get(l.node.field("axis"));
                w.set(node_l.field("axis"), axis);
                if axis == 3 {
                    let p = rec.get(l.node.field("first")) as u64;
                    let (line, slot) = l.split(p);
                    w.set(node_l.field("first"), (line * l.tris_per_line as u64 + slot) as i128);
                    w.set(node_l.field("count"), rec.get(l.node.field("count")));
                } else {
                    for f in ["clip0", "clip1"] {
                        w.set(node_l.field(f), rec.get(l.node.field(f)));
                    }
                    w.set(node_l.field("child"), rec.get(l.node.field("child")) - 1);
                }
                w
            })
            .collect();
        let mut tris = vec![Word::zero(tri_l.width); rom.tri.1.len()];
        let mut leaves = Vec::new();
        for k in 0..l.tri_records {
            let rec = self.tri(l.pointer(k));
            let t = rec.get(l.tri.field("id"));
            let mut w = rec.clone();
            w.0.truncate(tri_l.width.div_ceil(64) as usize);
            if tri_l.width % 64 != 0 {
                let last = w.0.len() - 1;
                w.0[last] &= (1u64 << (tri_l.width % 64)) - 1;
            }
            tris[t as usize] = w;
            let mut e = Word::zero(leaf_l.width);
            e.set(leaf_l.field("tri"), t);
            leaves.push(e);
        }
        if leaves.is_empty() {
            leaves.push(Word::zero(leaf_l.width));
        }
        (nodes, tris, leaves)
    }

    /// Writes the image (through a temporary file, so a failed write leaves nothing half done).
    pub fn write(&self, path: &Path) -> Result<()> {
        let mut files = crate::io::OutputSet::new();
        files.add(path, &self.bytes)?;
        files.commit()
    }

    /// Reads an image `build` wrote for `roms` and `shape`: its header must be the one
    /// `build` writes, its length the layout's. Errors name the file.
    pub fn read(path: &Path, roms: &SceneRoms, shape: MemoryShape) -> Result<SceneImage> {
        let bytes = std::fs::read(path).map_err(|e| Error::file(path, e.to_string()))?;
        let expected = SceneImage::build(roms, shape)?;
        let bad = |what: String| Err(Error::file(path, what));
        if bytes.len() < HEADER_BYTES || &bytes[..8] != MAGIC {
            return bad("not an fxrt scene image (no FXRTSCN1 header)".into());
        }
        if bytes[..HEADER_BYTES] != expected.bytes[..HEADER_BYTES] {
            return bad("its header (version, widths, line, record counts) is not this scene's and shape's".into());
        }
        if bytes.len() as u64 != expected.layout.total_bytes {
            return bad(format!("{} bytes, the layout needs {}", bytes.len(), expected.layout.total_bytes));
        }
        Ok(SceneImage { layout: expected.layout, bytes })
    }
}

fn put(bytes: &mut [u8], at: u64, len: u32, w: &Word) {
    let at = at as usize;
    for (k, b) in bytes[at..at + len as usize].iter_mut().enumerate() {
        *b = w.0.get(k / 8).map_or(0, |limb| (limb >> (8 * (k % 8))) as u8);
    }
}

fn get(bytes: &[u8], at: u64, len: u32) -> Word {
    let mut w = Word(vec![0; (len as usize).div_ceil(8)]);
    for (k, &b) in bytes[at as usize..at as usize + len as usize].iter().enumerate() {
        w.0[k / 8] |= (b as u64) << (8 * (k % 8));
    }
    w
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::Params;
    use crate::scene::Scene;
    use crate::scene::builtin::builtin_scene;

    fn roms(name: &str, params: &Params) -> SceneRoms {
        SceneRoms::of(&Scene::build(name, builtin_scene(name).unwrap(), params).unwrap())
    }

    /// Image → bytes on disk → read back → ROM words: the ROM images exactly, for scenes with
    /// empty leaves (random) and oversized ones, at every data width and a range of lines.
    #[test]
    fn image_round_trips_to_the_rom_images() {
        let dir = tempfile::tempdir().unwrap();
        for (name, params) in [
            ("teapot", Params::default()),
            ("random", Params { n: 12, m: 14, leaf_size: 3, ..Params::default() }),
            ("jackstraws", Params { leaf_size: 1, ..Params::default() }),
        ] {
            let r = roms(name, &params);
            for (mem_bits, line_bytes) in [(32, 64), (64, 128), (64, 256), (128, 128), (128, 4096)] {
                let shape = MemoryShape { mem_bits, line_bytes };
                let image = SceneImage::build(&r, shape).unwrap();
                let path = dir.path().join("scene.bin");
                image.write(&path).unwrap();
                let back = SceneImage::read(&path, &r, shape).unwrap();
                assert_eq!(back, image);
                let (nodes, tris, leaves) = back.to_rom_words(&r);
                assert_eq!(nodes, r.node.1, "{name} {shape:?}: nodes");
                assert_eq!(tris, r.tri.1, "{name} {shape:?}: triangles");
                assert_eq!(leaves, r.leaf.1, "{name} {shape:?}: leaf table");
            }
        }
    }

    /// The addresses the caches rely on: child pairs in one block, records inside one line,
    /// regions on line boundaries, every record inside the image.
    #[test]
    fn records_sit_where_the_caches_expect_them() {
        let r = roms("teapot", &Params::default());
        for shape in [MemoryShape::default(), MemoryShape { mem_bits: 128, line_bytes: 64 }] {
            let l = MemoryLayout::for_roms(&r, shape).unwrap();
            let line = shape.line_bytes as u64;
            assert_eq!(l.node_offset % line, 0);
            assert_eq!(l.tri_offset % line, 0);
            assert!(l.node_bytes.is_power_of_two() && l.node_bytes * 8 >= l.node.width);
            for i in 0..(l.node_records - 1) / 2 {
                let (a, b) = (l.node_address(2 * i + 2), l.node_address(2 * i + 3));
                assert_eq!(a / line, b / line, "pair {i} split over two lines");
                assert_eq!(a % (2 * l.node_bytes as u64), 0);
            }
            for k in 0..l.tri_records {
                assert_eq!(l.next(l.pointer(k)), l.pointer(k + 1));
                let at = l.tri_address(l.pointer(k));
                assert_eq!(at / line, (at + l.tri_bytes as u64 - 1) / line, "record {k} crosses a line");
                assert!(at + l.tri_bytes as u64 <= l.total_bytes);
            }
        }
        // Defaults: 76-bit nodes in 16 bytes; 284 + 13 bits of triangle in 40 bytes, 3 a line.
        let l = MemoryLayout::for_roms(&r, MemoryShape::default()).unwrap();
        assert_eq!((l.node_bytes, l.tri_bytes, l.tris_per_line, l.slot_bits), (16, 40, 3, 2));
    }

    #[test]
    fn a_changed_byte_or_shape_is_refused() {
        let r = roms("teapot", &Params::default());
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("scene.bin");
        let image = SceneImage::build(&r, MemoryShape::default()).unwrap();
        image.write(&path).unwrap();
        let other = MemoryShape { mem_bits: 128, line_bytes: 128 };
        let e = SceneImage::read(&path, &r, other).unwrap_err().to_string();
        assert!(e.contains("scene.bin") && e.contains("header"), "{e}");
        std::fs::write(&path, &image.bytes[..image.bytes.len() - 1]).unwrap();
        let e = SceneImage::read(&path, &r, MemoryShape::default()).unwrap_err().to_string();
        assert!(e.contains("bytes, the layout needs"), "{e}");
        for (mem_bits, line_bytes, param) in
            [(48, 128, "mem-bits"), (64, 96, "cache-line"), (128, 16, "cache-line"), (32, 32, "cache-line")]
        {
            let e = MemoryLayout::for_roms(&r, MemoryShape { mem_bits, line_bytes }).unwrap_err().to_string();
            assert!(e.contains(param), "{mem_bits} {line_bytes}: {e}");
        }
    }
}

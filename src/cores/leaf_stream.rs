//! The core's leaf stream (`top.rs` builds the rest around it): whole leaves taken in turn
//! from the traversal units' leaf queues, one triangle per clock from the leaf and triangle
//! ROMs into the intersection pipeline, with the ray read from the core's ray RAMs by slot.

use super::brom::rom_reads;
use super::core_params::{CoreParams, tri_rom_groups};
use super::intersect::intersect_core;
use super::ray_port::RayPort;
use super::traverse::{field, word_bits};
use super::wide_ram::{WideRam, address_registers, group_widths_of, runs};
use crate::rtl::Ty;
use crate::rtl::build::{Builder, Ports, S};
use crate::scene::images::SceneRoms;
use crate::scene::rom::rom_addr_bits;
use std::rc::Rc;

/// A lane's ray RAMs (origin and direction, for its pipeline), by slot within the lane,
/// written at the accept of a ray into one of the lane's slots: the origin RAM and the
/// direction RAMs.
pub struct RayRams {
    pub o: WideRam,
    /// One RAM of three directions while they fit a signal (m ≤ 42), else one per axis.
    pub w: Vec<WideRam>,
}

impl RayRams {
    /// How many read-address registers the emission's reads take: one per group of columns
    /// (`wide_ram`), 12 on the default core.
    pub fn read_groups(&self) -> usize {
        self.group_counts().iter().sum()
    }

    /// Each RAM's groups, the origins' RAM first (`CoreParams::ray_ram_widths` order).
    fn group_counts(&self) -> Vec<usize> {
        std::iter::once(&self.o).chain(&self.w).map(WideRam::groups).collect()
    }
}

pub fn ray_rams(b: &Builder, p: &CoreParams, port: &RayPort<'_>, lane: u32) -> RayRams {
    let (slots, lsb) = ((p.total_slots() >> p.lane_bits()) as usize, p.lane_slot_bits());
    // This lane's write enables and addresses, a register pair per group of columns.
    let groups = p.ray_ram_groups();
    let (wes, gslots) =
        (&port.ram_we[lane as usize * groups..][..groups], &port.ram_slots[lane as usize * groups..][..groups]);
    let (accept, gslot): (Vec<S>, Vec<S>) = match p.lane_bits() {
        0 => (wes.to_vec(), gslots.to_vec()),
        _ => wes
            .iter()
            .zip(gslots)
            .enumerate()
            .map(|(g, (&we, &slot))| {
                let mine = p.in_lane(slot, lane);
                ((we & mine).name(&p.lane_name(lane, &format!("ray_we{g}"))), slot.slice(0, lsb))
            })
            .unzip(),
    };
    let name = |x: &str| p.lane_name(lane, x);
    let [ox, oy, oz] = port.o;
    let [wx, wy, wz] = port.w;
    // The RAMs as `ray_ram_widths` lays them out, each made and then written its word in turn.
    let widths = p.ray_ram_widths();
    let counts: Vec<usize> =
        widths.iter().enumerate().map(|(k, &w)| group_widths_of(w, p.ray_ram_group_bits(k)).len()).collect();
    let (wes, ats) = (runs(&accept, &counts), runs(&gslot, &counts));
    let names: &[&str] = if widths.len() == 2 { &["ray_o", "ray_w"] } else { &["ray_o", "ray_wx", "ray_wy", "ray_wz"] };
    let word = |k: usize| match (k, widths.len()) {
        (0, _) => b.cat(&[oz, oy, ox]),
        (_, 2) => b.cat(&[wz.unsigned(), wy.unsigned(), wx.unsigned()]),
        _ => [wx, wy, wz][k - 1].unsigned(),
    };
    let mut rams: Vec<WideRam> = (0..widths.len())
        .map(|k| {
            let ram = WideRam::in_groups_of(b, &name(names[k]), widths[k], slots, p.ray_ram_group_bits(k));
            ram.write(b, &wes[k], &ats[k], word(k));
            ram
        })
        .collect();
    let o = rams.remove(0);
    RayRams { o, w: rams }
}

/// The leaf in flight: the registers the emission reads.
pub struct Leaf<'b> {
    pub valid: S<'b>,
    pub slot: S<'b>,
    pub ptr: S<'b>,
    pub tmin: S<'b>,
    pub sp: S<'b>,
    /// The entry now sent is the leaf's first, its last.
    pub first: S<'b>,
    pub last_entry: S<'b>,
}

/// Lane `lane`'s leaf in flight (slot within the lane, next entry, entries left, tmin, sp),
/// and the next leaf taken, in turn, from a unit's queue when the last entry goes. `trav` are
/// the lane's units' ports, `leaf_pop` the wires of their queues' pops.
pub fn leaf_stream<'b>(
    b: &'b Builder,
    p: &CoreParams,
    lane: u32,
    scene: &SceneRoms,
    trav: &[Ports<'b>],
    leaf_pop: &[S<'b>],
) -> Leaf<'b> {
    let (tp, gb, bit) = (&p.trav, p.lane_slot_bits(), Ty::BIT);
    b.stage(&p.lane_name(lane, "leaf_stream"), "the leaf in flight, and the next leaf from the units' queues in turn");
    let nm = |x: &str| p.lane_name(lane, x);
    let leaf_bits = rom_addr_bits(scene.leaf.1.len());
    let count_w = scene.node.0.field("count").width;
    let cur_valid = b.reg(&nm("leaf_active"), bit, Some(0));
    let cur_slot = b.reg(&nm("leaf_slot"), Ty::u(gb), None);
    let cur_ptr = b.reg(&nm("leaf_ptr"), Ty::u(leaf_bits), None);
    let cur_left = b.reg(&nm("leaf_left"), Ty::u(count_w), None);
    let cur_tmin = b.reg(&nm("leaf_tmin"), Ty::u(tp.tmin_width()), None);
    let cur_sp = b.reg(&nm("leaf_sp"), Ty::u(tp.sp_width()), None);
    let cur_first = b.reg(&nm("leaf_first_entry"), bit, None);
    // Whether the entry now sent is the leaf's last: a register of its own (left = 1 next).
    let cur_last = b.reg(&nm("leaf_last"), bit, None);
    let last_entry = (cur_valid & cur_last).name(&nm("leaf_last_entry"));
    let can_take = (!cur_valid | last_entry).name(&nm("leaf_can_take"));
    let picked = leaf_buffers(b, p, lane, trav, leaf_pop, can_take);
    let (take, sel) = (picked.take, |f: &str| picked.field(f));
    let next_slot = picked.slot();
    b.next(cur_valid, take | (cur_valid & !last_entry));
    b.next(cur_slot, take.select(next_slot, cur_slot));
    b.next(cur_ptr, take.select(sel("leaf_first"), cur_ptr + 1));
    b.next(cur_left, take.select(sel("leaf_count"), cur_left - 1));
    b.next(cur_tmin, take.select(sel("leaf_tmin"), cur_tmin));
    b.next(cur_sp, take.select(sel("leaf_sp"), cur_sp));
    b.next(cur_first, take);
    b.next(cur_last, take.select(sel("leaf_count").eq(1), cur_left.eq(2)));
    Leaf { valid: cur_valid, slot: cur_slot, ptr: cur_ptr, tmin: cur_tmin, sp: cur_sp, first: cur_first, last_entry }
}

/// The units' next leaves, each in a register of the top's, and the one taken when `can_take`.
pub struct Picked<'b> {
    b: &'b Builder,
    /// A leaf is taken this clock.
    pub take: S<'b>,
    /// The unit whose leaf is taken (with more than one), and each unit's buffered fields.
    pick_u: Option<S<'b>>,
    held: Vec<Vec<S<'b>>>,
}

const LEAF_FIELDS: [&str; 5] = ["leaf_slot", "leaf_first", "leaf_count", "leaf_tmin", "leaf_sp"];

impl<'b> Picked<'b> {
    /// A field of the leaf taken (`leaf_first`, `leaf_count`, `leaf_tmin`, `leaf_sp`; a select
    /// built at each call).
    pub fn field(&self, name: &str) -> S<'b> {
        let k = LEAF_FIELDS.iter().position(|f| *f == name).expect("a buffered leaf field");
        let v: Vec<S> = self.held.iter().map(|held| held[k]).collect();
        match self.pick_u {
            None => v[0],
            Some(u) => self.b.case(u, &v.iter().enumerate().map(|(k, x)| (k as u128, *x)).collect::<Vec<_>>(), v[0]),
        }
    }

    /// Its global slot: the unit number above the unit's slot.
    pub fn slot(&self) -> S<'b> {
        match self.pick_u {
            None => self.field("leaf_slot"),
            Some(u) => self.b.cat(&[u, self.field("leaf_slot")]),
        }
    }
}

/// Each unit's next leaf waits in a register of the top's (`leaf_buf`), filled from the unit's
/// queue while empty: the arbiter then chooses among registers beside it, and the queues (across
/// the die) only feed a register each. A unit's queue pops a clock after it is taken from
/// (`traverse_core`), and its buffer is full in that clock anyway. Taken in turn when `can_take`;
/// `trav` are the units of one lane (the slot taken is a slot within the lane).
pub fn leaf_buffers<'b>(
    b: &'b Builder,
    p: &CoreParams,
    lane: u32,
    trav: &[Ports<'b>],
    leaf_pop: &[S<'b>],
    can_take: S<'b>,
) -> Picked<'b> {
    let (units, bit) = (trav.len() as u32, Ty::BIT);
    let ub = p.unit_bits() - p.lane_bits();
    let leaf_turn = b.reg(&p.lane_name(lane, "leaf_turn"), Ty::u(ub.max(1)), Some(0));
    let first_unit = (lane * p.lane_units()) as usize;
    let fields = LEAF_FIELDS;
    let bufs: Vec<(S, S, Vec<S>)> = trav
        .iter()
        .enumerate()
        .map(|(k, t)| {
            let u = first_unit + k;
            let full = b.reg(&format!("u{u}_leaf_buf_valid"), bit, Some(0));
            let fill = (t.get("leaf_valid") & !full).name(&format!("u{u}_leaf_fill"));
            b.drive(leaf_pop[k], fill);
            let held: Vec<S> = fields
                .iter()
                .map(|f| {
                    let r = b.reg(&format!("u{u}_buf_{f}"), t.get(f).ty(), None);
                    b.next_when(r, fill, t.get(f));
                    r
                })
                .collect();
            (full, fill, held)
        })
        .collect();
    let avail: Vec<S> = bufs.iter().map(|(full, _, _)| *full).collect();
    let (any_leaf, pick_u) = rotating_pick(b, &avail, leaf_turn, ub);
    let take = (can_take & any_leaf).name(&p.lane_name(lane, "leaf_take"));
    for (k, &(full, fill, _)) in bufs.iter().enumerate() {
        let u = first_unit + k;
        let me = if units == 1 { take } else { (take & pick_u.eq(k as i128)).name(&format!("u{u}_leaf_take")) };
        b.next(full, fill | (full & !me));
    }
    if units > 1 {
        b.next_when(leaf_turn, take, pick_u);
    } else {
        b.next(leaf_turn, leaf_turn);
    }
    let held = bufs.into_iter().map(|(_, _, held)| held).collect();
    Picked { b, take, pick_u: (units > 1).then_some(pick_u), held }
}

/// Rotating priority among the units' buffered leaves (`avail`): the unit after the last one
/// served (`turn`) first. Returns whether any waits and the unit chosen.
fn rotating_pick<'b>(b: &'b Builder, avail: &[S<'b>], turn: S<'b>, ub: u32) -> (S<'b>, S<'b>) {
    let (units, bit) = (avail.len() as u32, Ty::BIT);
    let mut pick: Option<(S, S)> = None; // (any, unit)
    for j in (0..units).rev() {
        // Candidate j places after the turn: unit (turn + 1 + j) mod units.
        let cand = |u: u32| (u + 1 + j) % units;
        let sel_any = if units == 1 {
            avail[0]
        } else {
            b.case(turn, &(0..units).map(|t| (t as u128, avail[cand(t) as usize])).collect::<Vec<_>>(), b.konst(bit, 0))
        };
        let sel_u = if units == 1 {
            b.konst(Ty::u(1), 0)
        } else {
            b.case(
                turn,
                &(0..units).map(|t| (t as u128, b.konst(Ty::u(ub), cand(t) as i128))).collect::<Vec<_>>(),
                b.konst(Ty::u(ub), 0),
            )
        };
        pick = Some(match pick {
            None => (sel_any, sel_u),
            Some((any, u)) => (sel_any | any, sel_any.select(sel_u, u)),
        });
    }
    pick.expect("one unit or more")
}

/// The pipeline's input: the intersection pipeline's outputs and its valid input (`busy`).
pub struct Emission<'b> {
    pub pipe: Ports<'b>,
    pub valid: S<'b>,
}

/// Emission, per lane: the leaf ROM at the entry, then the triangle ROMs at its word; the tag
/// and the ray (read from the lane's ray RAMs at the slot) wait alongside, into the lane's
/// intersection pipeline. Two lanes share each ROM, on its two ports.
pub fn emission<'b>(
    b: &'b Builder,
    p: &CoreParams,
    scene: &SceneRoms,
    leaves: &[Leaf<'b>],
    rams: &[RayRams],
) -> Vec<Emission<'b>> {
    let (tp, scene_tag) = (&p.trav, &p.trav.scene_tag);
    b.stage("emission", "the leaf ROM, the triangle ROMs and the slot's ray, into the intersection pipeline");
    let (leaf_l, leaf_words) = &scene.leaf;
    let leaf_image: Vec<u128> = leaf_words.iter().map(|w| word_bits(w, 0, leaf_l.width)).collect();
    let lrc = tp.leaf_rom_cycles;
    let ptrs: Vec<S> = leaves.iter().map(|l| l.ptr).collect();
    // Labels as with one pipeline for the first ROM, `_1` after the second copy's.
    let label = |base: String| move |pair: usize| if pair == 0 { base.clone() } else { format!("{base}_{pair}") };
    let tri_nums =
        rom_reads(b, &label("u_leaf_rom".into()), &format!("leaf_{scene_tag}"), leaf_l.width, &leaf_image, &ptrs, lrc);
    let (tri_l, tri_words) = &scene.tri;
    let lanes: Vec<(S, S, S)> = leaves
        .iter()
        .zip(&tri_nums)
        .enumerate()
        .map(|(lane, (leaf, &tri_num))| {
            let nm = |x: &str| p.lane_name(lane as u32, x);
            let slot = match p.lane_bits() {
                0 => leaf.slot,
                lb => b.cat(&[b.konst(Ty::u(lb), lane as i128), leaf.slot]),
            };
            let tag = b.cat(&[leaf.last_entry, leaf.first, slot, leaf.sp, leaf.tmin, b.konst(Ty::u(tp.tri_bits), 0)]);
            let tag = b.delay_line(&nm("emit_tag"), tag, lrc);
            let tag = b
                .cat(&[tag.slice(tp.tri_bits, tag.width() - tp.tri_bits), tri_num.resize(tp.tri_bits)])
                .name(&nm("emit_tag_tri"));
            let emit_valid = b.valid_line(&nm("emit_valid"), leaf.valid, lrc);
            (tag, emit_valid, tri_num.resize(rom_addr_bits(tri_words.len())).name(&nm("tri_addr")))
        })
        .collect();
    let addrs: Vec<S> = lanes.iter().map(|l| l.2).collect();
    let mut tri_fields: Vec<Vec<S>> = vec![Vec::new(); leaves.len()];
    for (k, group) in tri_rom_groups(&tri_l.fields).iter().enumerate() {
        let lsb = group[0].lsb;
        let width: u32 = group.iter().map(|f| f.width).sum();
        let image: Vec<u128> = tri_words.iter().map(|w| word_bits(w, lsb, width)).collect();
        let name = format!("tri_{k}_{scene_tag}");
        let words = rom_reads(b, &label(format!("u_tri_rom_{k}")), &name, width, &image, &addrs, p.tri_rom_cycles);
        for (fields, word) in tri_fields.iter_mut().zip(words) {
            fields.extend(group.iter().map(|f| field(&format!("tri_{}", f.name), word, f, lsb)));
        }
    }
    let trc = p.tri_rom_cycles;
    let out = lanes.into_iter().zip(tri_fields).zip(leaves.iter().zip(rams)).enumerate();
    out.map(|(lane, (((tag, emit_valid, _), tri_fields), (leaf, rams)))| {
        let nm = |x: &str| p.lane_name(lane as u32, x);
        let valid_d = b.valid_line(&nm("pipe_valid"), emit_valid, trc);
        let tag_d = b.delay_line(&nm("pipe_tag"), tag, trc);
        // The slot's ray, read as the triangle ROMs are (its RAM read is one of the clocks), its
        // address from a register per ray RAM (the tag's slot bits fanned out to all of them).
        let slot = if lrc > 1 { b.delay_line(&nm("emit_slot_sr"), leaf.slot, lrc - 1) } else { leaf.slot };
        let emit_slot = b.delay(&nm("emit_slot"), slot);
        let emit_slots = address_registers(b, emit_slot, rams.read_groups());
        into_pipeline(b, p, (lane as u32, rams), &emit_slots, trc, [valid_d, tag_d], tri_fields)
    })
    .collect()
}

/// Lane `lane`'s intersection pipeline fed a triangle (`valid_tag`: its valid bit and tag,
/// `tri_fields`: its fields) and the ray of slot `slot` (within the lane), read from the lane's
/// ray RAMs `rams` `clocks` clocks before the triangle enters (the RAM read and `clocks` − 1 registers). `slot` holds the slot
/// once; several equal registers may share out the RAMs' read addresses (RAM k reads with
/// `slot[k % slot.len()]`, the origins' RAM first).
pub fn into_pipeline<'b>(
    b: &'b Builder,
    p: &CoreParams,
    (lane, rams): (u32, &RayRams),
    slot: &[S<'b>],
    clocks: u32,
    valid_tag: [S<'b>; 2],
    tri_fields: Vec<S<'b>>,
) -> Emission<'b> {
    let (n, m) = (p.isect.n, p.isect.m);
    // The address registers, a run of them for each RAM's groups in turn.
    let addrs = runs(slot, &rams.group_counts());
    let nm = |x: &str| p.lane_name(lane, x);
    let o_word = rams.o.read(b, &nm("ray_o_q"), &addrs[0]);
    let o_word = b.delay_line(&nm("pipe_o"), o_word, clocks - 1);
    let w_words: Vec<S> = rams
        .w
        .iter()
        .enumerate()
        .map(|(k, mem)| {
            let suffix = if rams.w.len() == 1 { String::new() } else { ["x", "y", "z"][k].to_string() };
            let q = mem.read(b, &nm(&format!("ray_w{suffix}_q")), &addrs[k + 1]);
            b.delay_line(&nm(&format!("pipe_w{suffix}")), q, clocks - 1)
        })
        .collect();
    let mut pipe_in = valid_tag.to_vec();
    pipe_in.extend((0..3).map(|a| o_word.slice(a * n, n)));
    pipe_in.extend(
        (0..3).map(|a| if w_words.len() == 1 { w_words[0].slice(a * m, m) } else { w_words[a as usize] }.signed()),
    );
    pipe_in.extend(tri_fields);
    let pipe = b.instance(&p.lane_name(lane, "u_intersect"), &Rc::new(intersect_core(&p.isect)), &pipe_in);
    Emission { pipe, valid: valid_tag[0] }
}

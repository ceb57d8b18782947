//! The leaf stream of an external-memory core (docs/MEMORY.md "Triangles"): a leaf's triangle
//! records are fetched through the triangle cache into a **staging RAM** (2^stage_bits records
//! per global slot: a slot has one leaf in flight at most) before the leaf goes to the
//! intersection pipeline, so the pipeline never waits on memory in the middle of a leaf.
//!
//! - **Fetch**: whole leaves, a record a clock, from the units' leaf buffers in turn
//!   (`leaf_buffers`) or — first — a leaf back from the retry queue once its lines are in. Each
//!   record not staged by an earlier pass is looked up in the triangle cache a clock later;
//!   `cache::LATENCY` clocks after that a hit is written to the staging RAM, a miss marks the
//!   leaf and keeps the latest fill it must wait for. At the leaf's last answer it goes to the
//!   ready queue if every record is staged, else to the retry queue with that fill number, and
//!   its missing records are fetched again once the fill is done (DECISIONS 109).
//! - **Emission**: leaves from the ready queue, a triangle a clock from the staging RAM (two
//!   clocks: the block's read and output register) with the slot's ray, into the pipeline.
//!
//! What it costs: the staging RAM (slots × 2^stage_bits records), a bit per record of it (what
//! is staged), and a clock per record of a leaf that missed on each retry.

use super::axi_read::Fill;
use super::brom::bram;
use super::cache::{Cache, LATENCY, Lookup, SEQ_BITS, bits_across, cache, ready_when_released, released};
use super::core_params::CoreParams;
use super::fifo::{fifo, unpack};
use super::leaf_stream::{Emission, RayRams, into_pipeline, leaf_buffers};
use super::memory_params::ExternalMemory;
use super::wide_ram::address_registers;
use crate::rtl::Ty;
use crate::rtl::build::{Builder, Ports, S};
use crate::scene::rom::Field;

/// What the fetch shows the observation ports: triangle lookups and hits answered this clock,
/// and a clock the pipeline took no triangle while a leaf waited for memory.
pub struct FetchObserved<'b> {
    pub looks: S<'b>,
    pub hits: S<'b>,
    pub stall: S<'b>,
}

/// Bits [f.lsb, f.lsb + f.width) of a record held as parts of 128 bits (least significant
/// first), with the field's sign.
fn record_field<'b>(b: &'b Builder, parts: &[S<'b>], f: &Field) -> S<'b> {
    let raw = bits_across(b, parts, 128, f.lsb, f.width).name(&format!("tri_{}", f.name));
    if f.signed { raw.signed() } else { raw }
}

/// The fetch, the triangle cache, the staging RAM and the emission into the pipeline. `fill`
/// is the read master's beats for the triangle cache; the cache's line requests go out on
/// `request` (valid, line number).
#[allow(clippy::too_many_arguments)]
pub fn tri_fetch<'b>(
    b: &'b Builder,
    p: &CoreParams,
    m: &ExternalMemory,
    trav: &[Ports<'b>],
    leaf_pop: &[S<'b>],
    fill: &Fill<'b>,
    request: (S<'b>, S<'b>),
    rams: &RayRams,
) -> (Emission<'b>, FetchObserved<'b>) {
    let (tp, gb, bit, l) = (&p.trav, p.tag.slot_bits, Ty::BIT, &m.layout);
    let (pb, cw, ib, tw, spw) =
        (tp.leaf_bits, tp.node_layout.field("count").width, m.stage_bits, tp.tmin_width(), tp.sp_width());
    b.stage("tri_fetch", "leaves' triangle records through the triangle cache into the staging RAM");
    let w_valid = b.reg("fetch_active", bit, Some(0));
    let reg = |name: &str, w: u32| b.reg(name, Ty::u(w), None);
    let (w_slot, w_ptr, w_idx, w_left) =
        (reg("fetch_slot", gb), reg("fetch_ptr", pb), reg("fetch_idx", ib), reg("fetch_left", cw));
    let (w_head, w_count, w_tmin, w_sp) =
        (reg("fetch_head", pb), reg("fetch_count", cw), reg("fetch_tmin", tw), reg("fetch_sp", spw));
    let w_last = b.reg("fetch_last", bit, None);
    // Whether this pass over the leaf is a retry: then records staged by an earlier pass are
    // not looked up again.
    let w_retry = b.reg("fetch_retry", bit, None);
    let last_entry = (w_valid & w_last).name("fetch_last_entry");
    let can_take = (!w_valid | last_entry).name("fetch_can_take");

    // The retry queue: (slot, first, count, tmin, sp, fill to wait for), pushed at a leaf's
    // last answer.
    let retry_widths = [gb, pb, cw, tw, spw, SEQ_BITS];
    let retry_w: u32 = retry_widths.iter().sum();
    let (retry_push, retry_entry) = (b.wire("tri_retry_push", bit), b.wire("tri_retry_entry", Ty::u(retry_w)));
    let retry_pop = b.wire("tri_retry_pop", bit);
    let slots = p.total_slots();
    let retry = fifo(b, "tri_retry_q", retry_w, slots, retry_push, retry_entry, retry_pop);
    let r = unpack(retry.head, &retry_widths);
    let tri_done = b.wire("tri_done", Ty::u(SEQ_BITS));
    let retry_ready = ready_when_released(b, "tri_retry", retry.nonempty, tri_done, r[5], retry_pop);
    let take_retry = (can_take & retry_ready).name("fetch_take_retry");
    b.drive(retry_pop, take_retry);
    let picked = leaf_buffers(b, p, 0, trav, leaf_pop, (can_take & !retry_ready).name("fetch_can_take_leaf"));
    let take = (take_retry | picked.take).name("fetch_take");
    let src = |k: usize, leaf_field: &str| take_retry.select(r[k], picked.field(leaf_field));
    let (first, count) = (src(1, "leaf_first"), src(2, "leaf_count"));
    b.next(w_valid, take | (w_valid & !last_entry));
    b.next(w_slot, take.select(take_retry.select(r[0], picked.slot()), w_slot));
    // The next record: the next slot of the line, or slot 0 of the next line.
    let sb = l.slot_bits;
    let next_ptr = if sb == 0 {
        w_ptr + 1
    } else {
        let line_end = w_ptr.slice(0, sb).eq((l.tris_per_line - 1) as i128);
        line_end.select(((w_ptr >> sb) + 1) << sb, w_ptr + 1).name("fetch_next_ptr")
    };
    b.next(w_ptr, take.select(first, next_ptr));
    b.next(w_idx, take.select(w_idx.k(0), w_idx + 1));
    b.next(w_left, take.select(count, w_left - 1));
    b.next(w_last, take.select(count.eq(1), w_left.eq(2)));
    b.next_when(w_head, take, first);
    b.next_when(w_count, take, count);
    b.next_when(w_tmin, take, src(3, "leaf_tmin"));
    b.next_when(w_sp, take, src(4, "leaf_sp"));
    b.next_when(w_retry, take, take_retry);

    // Which records of a slot's leaf are in the staging RAM: written at every answer of every
    // pass (so a leaf's first pass overwrites what an earlier leaf left), read a clock before
    // the lookup. A record staged stays staged until its leaf is emitted, so every line that
    // arrives and is hit once moves its leaf forward for good: a leaf whose lines evict each
    // other (or are evicted by other slots' fills) still finishes.
    // The flags are a block RAM module read through the block's output register, two clocks
    // after the address (read straight from a DP16KD into the lookup's valid it was 10.45 ns
    // at seed 1 of the teapot-fine external core): the lookup enters the cache and a record
    // staged before is withdrawn after the cache's first register (`Lookup::cancel`).
    let stage_words = (slots as usize) << ib;
    let (stage_we, stage_waddr, stage_flag) =
        (b.wire("stage_flag_we", bit), b.wire("stage_waddr", Ty::u(gb + ib)), b.wire("stage_flag", bit));
    let shape = format!("stage_flags_d{stage_words}");
    let raddr = b.cat(&[w_slot, w_idx]);
    let staged_r = bram(b, "u_tri_staged", &shape, 1, stage_words, stage_we, stage_waddr, stage_flag, raddr);
    let f_valid = b.valid_delay("fetch1_valid", w_valid);
    let f_retry = b.delay("fetch1_retry", w_retry);
    let skip = (b.valid_delay("fetch2_retry", f_valid & f_retry) & staged_r).name("fetch2_staged");

    let rec = if sb == 0 { b.konst(Ty::u(m.tri.rec_bits()), 0) } else { w_ptr.slice(0, sb).resize(m.tri.rec_bits()) };
    let look = Lookup {
        valid: f_valid,
        line: b.delay("fetch1_line", (w_ptr >> sb).resize(m.tri.line_bits)),
        rec: b.delay("fetch1_rec", rec),
        cancel: Some(skip),
    };
    let Cache { answer, request: (req_valid, req_line), done } = cache(b, "tc", &m.tri, &look, fill);
    b.drive(request.0, req_valid);
    b.drive(request.1, req_line);
    b.drive(tri_done, done);

    b.stage("tri_answer", "the answers: hits into the staging RAM; a leaf with a miss to the retry queue");
    let tag = b.cat(&[w_slot, w_idx, w_head, w_count, w_tmin, w_sp, w_last]);
    let a = unpack(b.delay_line("fetch_tag", tag, LATENCY + 1), &[gb, ib, pb, cw, tw, spw, 1]);
    let (a_slot, a_idx, a_last) = (a[0], a[1], a[6]);
    // Every record of a pass is answered: by the cache, or as staged before.
    let av = b.valid_line("fetch_answered", w_valid, LATENCY + 1);
    let a_skip = b.delay_line("fetch_skip", skip, LATENCY - 1);
    let looked_hit = (answer.valid & answer.hit).name("tri_hit");
    let good = (a_skip | looked_hit).name("fetch_good");
    let acc_miss = b.reg("fetch_missed", bit, Some(0));
    let acc_wait = b.reg("fetch_wait", Ty::u(SEQ_BITS), None);
    let earlier = (a_idx.ne(0) & acc_miss).name("fetch_missed_before");
    let missed = (earlier | !good).name("fetch_missed_c");
    // The later of the fills to wait for (fills are numbered in order, compared as serial numbers).
    let later = (earlier & released(acc_wait, answer.wait)).name("fetch_wait_keep");
    let wait = (good | later).select(acc_wait, answer.wait).name("fetch_wait_c");
    b.next_when(acc_miss, av, missed);
    b.next_when(acc_wait, av, wait);
    let leaf_done = (av & a_last).name("fetch_leaf_done");
    b.drive(retry_push, leaf_done & missed);
    b.drive(retry_entry, b.cat(&[a_slot, a[2], a[3], a[4], a[5], wait]));
    let ready_widths = [gb, cw, tw, spw];
    let ready_push = (leaf_done & !missed).name("fetch_ready");
    let ready_pop = b.wire("ready_pop", bit);
    let ready =
        fifo(b, "ready_q", ready_widths.iter().sum(), slots, ready_push, b.cat(&[a_slot, a[3], a[4], a[5]]), ready_pop);
    b.drive(stage_waddr, b.cat(&[a_slot, a_idx]));
    b.drive(stage_we, av);
    b.drive(stage_flag, good);
    let (waddr, we) = (stage_waddr, looked_hit);

    b.stage("tri_emit", "leaves from the ready queue, a triangle a clock from the staging RAM into the pipeline");
    let e_valid = b.reg("emit_active", bit, Some(0));
    let (e_slot, e_idx, e_left) = (reg("emit_slot", gb), reg("emit_idx", ib), reg("emit_left", cw));
    let (e_tmin, e_sp) = (reg("emit_tmin", tw), reg("emit_sp", spw));
    let (e_first, e_last) = (b.reg("emit_first", bit, None), b.reg("emit_last", bit, None));
    let e_last_entry = (e_valid & e_last).name("emit_last_entry");
    let e_take = ((!e_valid | e_last_entry) & ready.nonempty).name("emit_take");
    b.drive(ready_pop, e_take);
    let h = unpack(ready.head, &ready_widths);
    b.next(e_valid, e_take | (e_valid & !e_last_entry));
    b.next(e_slot, e_take.select(h[0], e_slot));
    b.next(e_idx, e_take.select(e_idx.k(0), e_idx + 1));
    b.next(e_left, e_take.select(h[1], e_left - 1));
    b.next(e_last, e_take.select(h[1].eq(1), e_left.eq(2)));
    b.next(e_first, e_take);
    b.next_when(e_tmin, e_take, h[2]);
    b.next_when(e_sp, e_take, h[3]);
    let raddr = b.cat(&[e_slot, e_idx]).name("stage_raddr");
    let parts: Vec<S> = m
        .tri
        .parts()
        .iter()
        .enumerate()
        .zip(&answer.data)
        .map(|((j, &w), &data)| {
            bram(b, &format!("u_stage_{j}"), &format!("stage_{j}_w{w}"), w, stage_words, we, waddr, data, raddr)
        })
        .collect();
    // Two clocks: the staging RAM's read and output register; the slot's ray alongside.
    let lat = 2;
    let valid_d = b.valid_line("pipe_valid", e_valid, lat);
    let tag = b.delay_line("pipe_tag_leaf", b.cat(&[e_last_entry, e_first, e_slot, e_sp, e_tmin]), lat);
    let id = record_field(b, &parts, l.tri.field("id"));
    let tag = b.cat(&[tag, id.resize(tp.tri_bits)]).name("pipe_tag");
    let fields = l.tri.fields.iter().filter(|f| f.name != "id").map(|f| record_field(b, &parts, f)).collect();
    // The slot addresses the ray RAMs, ~180 LUT-RAM slices and their bank selects: a copy per
    // group of columns splits that fan-out (935 sinks a bit on the teapot-fine core).
    let slot_copies = address_registers(b, e_slot, rams.read_groups());
    let emitted = into_pipeline(b, p, (0, rams), &slot_copies, lat, [valid_d, tag], fields);
    let stall = b.delay("mem_stall", (!valid_d & retry.nonempty).name("mem_stall_c"));
    let observed = FetchObserved { looks: answer.valid, hits: looked_hit, stall };
    (emitted, observed)
}

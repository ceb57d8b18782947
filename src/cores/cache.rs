//! A read-only cache of scene records in front of the AXI read master (docs/MEMORY.md "The
//! caches"): set-associative, lines of whole records, one lookup a clock, answered `LATENCY` (5)
//! clocks later — a hit with the record, or a miss with the **fill number to wait
//! for**. Misses never block: the asker parks what missed and asks again once `done` has
//! reached that number. Fills are numbered in the order the cache asked for them, and the
//! memory answers in order, so "line k arrived" is one counter compare; a miss to a line
//! already on its way gets that line's number (misses to one line are merged); a miss when
//! every in-flight place is taken waits for the next fill and asks again.
//!
//! Fills: a line's first beat writes the victim's tag word (valid bit and tag, in the tag RAM)
//! invalid, every record is written the clock its last beat comes, the last beat writes the new
//! tag word valid. A lookup reads tag word and record in one clock, so it sees either the old
//! line whole or a miss; a tag read in the clock its word is written is taken as a miss (the
//! block RAM's read is not defined then). The one-clock reset starts a sweep that writes one
//! set's tag words invalid a clock; until it ends nothing hits and nothing is asked for. A line
//! stays in the in-flight table until its first hit, and no fill is asked for into a set with a
//! line in the table, so every line that arrives is hit once before it can leave (DECISIONS
//! 109, 113). The victim way is a round-robin counter (no per-set state;
//! examples/memory_study.rs: 8 % more bytes than LRU at 64 KB).

use super::axi_read::Fill;
use crate::bits::addr_bits;
use crate::rtl::Ty;
use crate::rtl::build::{Builder, S};

/// Clocks from a lookup to its answer: the input register, the RAM read, a fabric register
/// after it, the compare (while the in-flight table is searched), the decision.
pub const LATENCY: u32 = 5;

/// Bits of a fill number (wrapping; compared as serial numbers, so a waiter may wait up to
/// 2^15 fills).
pub const SEQ_BITS: u32 = 16;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CacheParams {
    /// Bits of a record the asker uses (the low bits of its beats).
    pub record_bits: u32,
    /// Beats a record takes in memory.
    pub record_beats: u32,
    pub records_per_line: u32,
    pub line_beats: u32,
    pub data_bits: u32,
    /// Sets (a power of two) and ways (1, 2 or 4).
    pub sets: u32,
    pub ways: u32,
    /// Bits of a line number.
    pub line_bits: u32,
    /// Lines in flight at most (a power of two).
    pub inflight: u32,
}

impl CacheParams {
    pub fn set_bits(&self) -> u32 {
        self.sets.trailing_zeros()
    }
    pub fn rec_bits(&self) -> u32 {
        addr_bits(self.records_per_line as usize)
    }
    /// The widths of the RAMs a record is split into (a signal holds at most 128 bits).
    pub fn parts(&self) -> Vec<u32> {
        let k = self.record_bits.div_ceil(128);
        (0..k).map(|j| (self.record_bits - 128 * j).min(128)).collect()
    }
    /// Bits the cache holds: records and tags.
    pub fn bits(&self) -> u64 {
        let words = (self.sets * self.ways) as u64 * self.records_per_line.next_power_of_two() as u64;
        words * self.record_bits as u64 + (self.sets * self.ways) as u64 * (1 + self.line_bits - self.set_bits()) as u64
    }
}

/// A lookup: record `rec` of line `line`.
pub struct Lookup<'b> {
    pub valid: S<'b>,
    pub line: S<'b>,
    pub rec: S<'b>,
    /// A register that withdraws the lookup a clock after `valid` (the node's cull test, known
    /// a clock late): the lookup goes no further than the cache's first register, which then
    /// never sees the cull test's carry chain (10.5 ns into it at a seed of the external core).
    pub cancel: Option<S<'b>>,
}

/// The answer, `LATENCY` clocks after the lookup.
pub struct Answer<'b> {
    pub valid: S<'b>,
    pub hit: S<'b>,
    /// The record (parts, least significant first) when `hit`.
    pub data: Vec<S<'b>>,
    /// When a miss: wait until `released(done, wait)`, then look again.
    pub wait: S<'b>,
}

pub struct Cache<'b> {
    pub answer: Answer<'b>,
    /// A line to fetch (its number): at most one a clock, at most `inflight` unanswered.
    pub request: (S<'b>, S<'b>),
    /// The number of the last fill written (0 before any).
    pub done: S<'b>,
}

/// Bits [lsb, lsb + width) of a value held as `words` of `word_bits` each (least significant
/// first; the last may be narrower): a record across beats, or across a record's parts.
pub fn bits_across<'b>(b: &'b Builder, words: &[S<'b>], word_bits: u32, lsb: u32, width: u32) -> S<'b> {
    let mut pieces = Vec::new();
    let mut at = lsb;
    while at < lsb + width {
        let (k, off) = (at / word_bits, at % word_bits);
        let take = (words[k as usize].width() - off).min(lsb + width - at);
        pieces.push(words[k as usize].slice(off, take));
        at += take;
    }
    pieces.reverse();
    if pieces.len() == 1 { pieces[0] } else { b.cat(&pieces) }
}

/// Whether a waiter for fill `wait` may look again: `done` has reached it (serial-number
/// compare: done − wait, wrapped, is below half the range).
pub fn released<'b>(done: S<'b>, wait: S<'b>) -> S<'b> {
    !(done - wait).msb()
}

/// Whether the head of a retry queue (`nonempty`, waiting for fill `wait`) may go, in a
/// register: the 16-bit subtract behind the queue's head then ends at a flip-flop instead of
/// reaching the pop, the queue's read pointer and its LUT-RAM (the external core's slowest
/// paths: the node retry queue's at 60 MHz, then the triangle one's at 69.6). A head released
/// in clock c is ready in c + 1: `released` stays true once true, and the head changes only by
/// a `pop`, after which the next head waits a clock.
pub fn ready_when_released<'b>(
    b: &'b Builder,
    name: &str,
    nonempty: S<'b>,
    done: S<'b>,
    wait: S<'b>,
    pop: S<'b>,
) -> S<'b> {
    let now = (nonempty & released(done, wait) & !pop).name(&format!("{name}_released"));
    let ready = b.reg(&format!("{name}_ready"), Ty::BIT, Some(0));
    b.next(ready, now);
    ready
}

pub fn cache<'b>(b: &'b Builder, name: &str, p: &CacheParams, look: &Lookup<'b>, fill: &Fill<'b>) -> Cache<'b> {
    assert!(p.sets.is_power_of_two() && p.sets >= 2 && [1, 2, 4].contains(&p.ways) && p.inflight.is_power_of_two());
    let nm = |s: &str| format!("{name}_{s}");
    let (sb, rb, tb) = (p.set_bits(), p.rec_bits(), p.line_bits - p.set_bits());
    let wb = addr_bits(p.ways as usize);
    let parts = p.parts();
    let seq = Ty::u(SEQ_BITS);
    let depth_words = (p.sets << rb) as usize;
    // A tag word is the line's upper bits with a valid bit on top. The valid bits live in the
    // tag RAMs, not in flip-flops (512-set arrays of them, each with its own set decode, were
    // what kept the teapot-fine core from routing): after the one-clock reset a sweep clears
    // one set a clock, and until it ends no lookup hits and no fill is asked for.
    // Each way's tag RAM is a block RAM module read through the block's output register (the
    // tag word went from a DP16KD without it through the routing into a fabric register:
    // 10.63 ns at seed 1 of the teapot-fine external core). Its write port is driven by the
    // fill stage, its read port by the lookup.
    let mut tag_writes: Vec<S<'b>> = Vec::new();

    b.stage(&nm("fill"), "beats gathered into records and written; the victim's tag cleared at the first beat, the new one written at the last");
    let done = b.reg(&nm("done"), seq, Some(0));
    // The number the next fill asked for gets (the last asked for + 1), and how many are asked
    // for and not done: registers, so the decision needs no adder and no compare of numbers.
    let new_seq = b.reg(&nm("new_seq"), seq, Some(1));
    let pending = b.reg(&nm("pending"), Ty::u(addr_bits(p.inflight as usize + 1) + 1), Some(0));
    let db = addr_bits(p.inflight as usize);
    // The in-flight table, by fill number mod `inflight`: line, way, live.
    let slots: Vec<(S<'b>, S<'b>, S<'b>)> = (0..p.inflight)
        .map(|j| {
            (
                b.reg(&nm(&format!("fl{j}_line")), Ty::u(p.line_bits), None),
                b.reg(&nm(&format!("fl{j}_way")), Ty::u(wb), None),
                b.reg(&nm(&format!("fl{j}_live")), Ty::BIT, Some(0)),
            )
        })
        .collect();
    let next_fill = (done + 1).name(&nm("next_fill"));
    // The line and way of fill done + 1, in registers (the beats of one fill may follow the
    // last beat of the one before on the next clock; a select over the table from `done` would
    // sit between the counter and every RAM's write port). Loaded from the table's next entry
    // when a fill ends, or from the decision when it asks for exactly that fill.
    let f_line = b.reg(&nm("fill_line"), Ty::u(p.line_bits), None);
    let f_way = b.reg(&nm("fill_way"), Ty::u(wb), None);
    // (done + 2) mod inflight: the table's entry for the fill after the next, kept in a register.
    let after = b.reg(&nm("after_next"), Ty::u(db), Some(2 % (1i128 << db)));
    let pick = |f: &dyn Fn(&(S<'b>, S<'b>, S<'b>)) -> S<'b>, ty: Ty| {
        slots.iter().enumerate().fold(b.konst(ty, 0), |acc, (j, s)| after.eq(j as i128).select(f(s), acc))
    };
    let table_line = pick(&|s| s.0, Ty::u(p.line_bits)).name(&nm("table_line"));
    let table_way = pick(&|s| s.1, Ty::u(wb)).name(&nm("table_way"));
    // Driven by the decision below: it asks for fill `asked_seq` of line `asked_line` into way
    // `asked_way` this clock.
    let asked = b.wire(&nm("asked"), Ty::BIT);
    let asked_line = b.wire(&nm("asked_line"), Ty::u(p.line_bits));
    let asked_way = b.wire(&nm("asked_way"), Ty::u(wb));
    let f_set = f_line.slice(0, sb).name(&nm("fill_set"));
    let first = (fill.valid & fill.beat.eq(0)).name(&nm("fill_first"));
    let last = (fill.valid & fill.last).name(&nm("fill_last"));
    // Record assembly: the beats before a record's last, oldest at 0.
    let held: Vec<S<'b>> =
        (0..p.record_beats - 1).map(|k| b.reg(&nm(&format!("beat{k}")), fill.data.ty(), None)).collect();
    for k in 0..held.len() {
        let src = if k + 1 < held.len() { held[k + 1] } else { fill.data };
        b.next_when(held[k], fill.valid, src);
    }
    let in_rec = b.reg(&nm("in_rec"), Ty::u(addr_bits(p.record_beats as usize)), Some(0));
    let rec_no = b.reg(&nm("rec_no"), Ty::u(addr_bits(p.records_per_line as usize + 1)), Some(0));
    let rec_end = in_rec.eq((p.record_beats - 1) as i128).name(&nm("rec_end"));
    let write_rec = (fill.valid & rec_end & rec_no.lt(p.records_per_line as i128)).name(&nm("write_rec"));
    let in_rec_next = fill.valid.select((rec_end | fill.last).select(in_rec.k(0), in_rec + 1), in_rec);
    let rec_no_next = fill.valid.select(fill.last.select(rec_no.k(0), rec_end.select(rec_no + 1, rec_no)), rec_no);
    b.next(in_rec, in_rec_next.name(&nm("in_rec_next")));
    b.next(rec_no, rec_no_next.name(&nm("rec_no_next")));
    let beats: Vec<S<'b>> = held.iter().copied().chain([fill.data]).collect();
    let record = |lsb: u32, w: u32| bits_across(b, &beats, p.data_bits, lsb, w);
    let waddr = b.cat(&[f_set, rec_no.resize(rb)]).name(&nm("fill_addr"));
    // The record RAMs' write ports, by way and part: (enable, data); the RAMs are made with
    // their read ports below.
    let writes: Vec<Vec<(S<'b>, S<'b>)>> = (0..p.ways)
        .map(|w| {
            let we = || (write_rec & f_way.eq(w as i128)).name(&nm(&format!("write{w}")));
            let mut lsb = 0;
            parts
                .iter()
                .enumerate()
                .map(|(j, &pw)| {
                    let data = record(lsb, pw).name(&nm(&format!("rec{w}_{j}")));
                    lsb += pw;
                    let name = nm(&format!("write{w}_{j}"));
                    let next = [in_rec_next, rec_no_next];
                    (early_write_enable(b, &name, p, fill, next, f_way, w).unwrap_or_else(we), data)
                })
                .collect()
        })
        .collect();
    let sweep = b.reg(&nm("sweep"), Ty::u(sb + 1), Some(0));
    let sweeping = (!sweep.msb()).name(&nm("sweeping"));
    b.next_when(sweep, sweeping, sweep + 1);
    let valid_bit = last & !sweeping;
    let tag_word = if tb == 0 { valid_bit } else { b.cat(&[valid_bit, f_line.slice(sb, tb)]) };
    let tag_addr = sweeping.select(sweep.slice(0, sb), f_set).name(&nm("tag_addr"));
    let tag_data = sweeping.select(b.konst(Ty::u(tb + 1), 0), tag_word).name(&nm("tag_data"));
    for w in 0..p.ways {
        let way = f_way.eq(w as i128).name(&nm(&format!("fill_way{w}")));
        // The first beat writes the tag invalid (the victim's records are overwritten from
        // now on), the last writes it valid.
        tag_writes.push(((first | last) & way).name(&nm(&format!("tag_fill{w}"))));
    }
    b.next_when(done, last, next_fill);
    b.next_when(after, last, after + 1);
    // The fill asked for this clock is the next to arrive: nothing else was pending, or only
    // the one whose last beat is this clock.
    let next_is_asked = last.select(pending.eq(1), pending.eq(0));
    let from_decision = (asked & next_is_asked).name(&nm("fill_from_decision"));
    b.next(pending, pending + asked.resize(pending.width()) - last.resize(pending.width()));
    b.next_when(f_line, last | from_decision, from_decision.select(asked_line, table_line));
    b.next_when(f_way, last | from_decision, from_decision.select(asked_way, table_way));
    b.end_stage();

    b.stage(
        &nm("look"),
        "the lookup registered, tags and records read, compared; a miss merged or given a new fill number",
    );
    let l0_valid = b.valid_delay(&nm("l0_valid"), look.valid);
    let l0_line = b.delay(&nm("l0_line"), look.line);
    let l0_rec = b.delay(&nm("l0_rec"), look.rec.resize(rb));
    let set = l0_line.slice(0, sb);
    let raddr = b.cat(&[set, l0_rec]);
    // The tag words two clocks after `set`. A DP16KD's read of the word its other port writes
    // in the same clock is not defined, so such a read is taken as a miss (`tag_clash`): at a
    // fill's last beat the word read first was invalid anyway (its first beat wrote it so), and
    // at its first beat the victim's line, still valid until then, is missed once.
    let tag_r: Vec<S<'b>> = tag_writes
        .iter()
        .enumerate()
        .map(|(w, &fill_w)| {
            let (label, shape) = (nm(&format!("tag{w}")), format!("cache_tag_w{}_d{}", tb + 1, p.sets));
            let we = sweeping | fill_w;
            super::brom::bram(b, &format!("u_{label}"), &shape, tb + 1, p.sets as usize, we, tag_addr, tag_data, set)
        })
        .collect();
    let clash: Vec<S<'b>> = tag_writes
        .iter()
        .enumerate()
        .map(|(w, &fill_w)| {
            let now = (fill_w & f_set.eq(set)).name(&nm(&format!("tag_clash{w}_c")));
            b.valid_line(&nm(&format!("tag_clash{w}")), now, 2)
        })
        .collect();
    // A lookup may hit only if its tags were read after the sweep (2 clocks on: with `tag_r`).
    let swept_r = b.valid_line(&nm("swept_r"), !sweeping, 2);
    // The records two clocks after `raddr`: the RAM's read register and a second register
    // after it (the block RAM's output sits far from the logic).
    let data_r: Vec<Vec<S<'b>>> = writes
        .iter()
        .enumerate()
        .map(|(w, parts_w)| {
            parts_w
                .iter()
                .enumerate()
                .map(|(j, &(we, data))| {
                    record_ram(b, &nm(&format!("data{w}_{j}")), p, depth_words, we, waddr, data, raddr)
                })
                .collect()
        })
        .collect();
    // The in-flight table is searched for the line meanwhile.
    let l0_kept = match look.cancel {
        Some(cancel) => (l0_valid & !cancel).name(&nm("l0_kept")),
        None => l0_valid,
    };
    let l1_valid = b.valid_delay(&nm("l1_valid"), l0_kept);
    let l1_line = b.delay(&nm("l1_line"), l0_line);
    // The compare, while the in-flight table is searched for the line; both registered.
    let l2_valid = b.valid_delay(&nm("l2_valid"), l1_valid);
    let l2_line = b.delay(&nm("l2_line"), l1_line);
    // The tag word wanted: valid, and the line's upper bits.
    let one = b.konst(Ty::BIT, 1);
    let want = if tb == 0 { one } else { b.cat(&[one, l2_line.slice(sb, tb)]) };
    let same: Vec<S<'b>> = tag_r.iter().enumerate().map(|(w, &t)| t.eq(want).name(&nm(&format!("same{w}")))).collect();
    let hit_c: Vec<S<'b>> =
        same.iter().enumerate().map(|(w, &e)| (swept_r & !clash[w] & e).name(&nm(&format!("hit{w}_c")))).collect();
    let hits: Vec<S<'b>> = hit_c.iter().enumerate().map(|(w, &h)| b.delay(&nm(&format!("hit{w}")), h)).collect();
    // The record is picked by the tag compare alone (the sweep and the clash only withdraw a
    // hit; the ~250 select LUTs took them in at 9.5 ns at seed 2): a line is valid in at most
    // one way of its set (a fill is asked for only at a miss with no fill of the line in
    // flight), and without a hit the record is not used.
    let data: Vec<S<'b>> = (0..parts.len())
        .map(|j| {
            let d = (1..p.ways as usize).fold(data_r[0][j], |acc, w| same[w].select(data_r[w][j], acc));
            b.delay(&nm(&format!("data_s{j}")), d)
        })
        .collect();
    let mut found = b.konst(Ty::BIT, 0);
    let mut found_seq = b.konst(seq, 0);
    let mut busy = b.konst(Ty::BIT, 0);
    // Each place keeps its fill number (a register, not req minus the distance: that was a
    // subtractor per place on the path to the decision).
    let seqs: Vec<S<'b>> = (0..p.inflight).map(|j| b.reg(&nm(&format!("fl{j}_seq")), seq, None)).collect();
    let mut matched = Vec::new();
    for (j, s) in slots.iter().enumerate() {
        let m = (s.2 & s.0.eq(l2_line)).name(&nm(&format!("match{j}")));
        matched.push(b.delay(&nm(&format!("match_r{j}")), m));
        // An OR of the matches' numbers rather than a chain of selects (8 in series were
        // 10.25 ns at seed 2 of the external core): a line is in the table at most once (a
        // miss takes a place only when no place holds its line: `found`, `same_as_prev`).
        found_seq = found_seq | m.select(seqs[j], seqs[j].k(0));
        found = found | m;
        busy = busy | (s.2 & s.0.slice(0, sb).eq(l2_line.slice(0, sb)));
    }
    let l3_valid = b.valid_delay(&nm("l3_valid"), l2_valid);
    let l3_line = b.delay(&nm("l3_line"), l2_line);
    let found2 = b.delay(&nm("found_r"), found);
    let found_seq2 = b.delay(&nm("found_seq_r"), found_seq);
    // The decision. The table was searched a clock ago: a fill asked for by the lookup just
    // before this one is not in that search, so its line was compared with this one's then.
    let same_line = b.delay(&nm("same_line"), l2_line.eq(l3_line).name(&nm("same_line_c")));
    let same_set = b.delay(&nm("same_set"), l2_line.slice(0, sb).eq(l3_line.slice(0, sb)).name(&nm("same_set_c")));
    let busy2 = b.delay(&nm("busy_r"), busy.name(&nm("busy_c")));
    let hit = hits.iter().skip(1).fold(hits[0], |a, &h| a | h).name(&nm("hit"));
    let prev_alloc = b.reg(&nm("prev_alloc"), Ty::BIT, Some(0));
    let prev_seq = b.reg(&nm("prev_seq"), seq, None);
    let same_as_prev = (prev_alloc & same_line).name(&nm("same_as_prev"));
    let found = (found2 | same_as_prev).name(&nm("found"));
    let found_seq = same_as_prev.select(prev_seq, found_seq2).name(&nm("found_seq"));
    let slot_free = !slots
        .iter()
        .enumerate()
        .fold(b.konst(Ty::BIT, 0), |acc, (j, s)| acc | (new_seq.slice(0, db).eq(j as i128) & s.2));
    let miss = (l3_valid & !hit).name(&nm("miss"));
    let victim = b.reg(&nm("victim"), Ty::u(wb), Some(0));
    // While the tags are swept nothing is asked for (its tag write would be lost).
    let blocked = (busy2 | (prev_alloc & same_set) | sweeping).name(&nm("blocked"));
    let alloc = (miss & !found & slot_free & !blocked).name(&nm("alloc"));
    b.next(prev_alloc, alloc);
    b.next(prev_seq, new_seq);
    b.next_when(victim, alloc, if p.ways == 1 { victim } else { victim + 1 });
    b.drive(asked, alloc);
    b.drive(asked_line, l3_line);
    b.drive(asked_way, victim);
    b.next_when(new_seq, alloc, new_seq + 1);
    for (j, s) in slots.iter().enumerate() {
        let mine = (alloc & new_seq.slice(0, db).eq(j as i128)).name(&nm(&format!("alloc{j}")));
        b.next_when(s.0, mine, l3_line);
        b.next_when(s.1, mine, victim);
        b.next_when(seqs[j], mine, new_seq);
        // A line leaves the table at its first hit (found in the table a clock before).
        let freed = l3_valid & hit & matched[j];
        b.next(s.2, mine.select(b.konst(Ty::BIT, 1), freed.select(b.konst(Ty::BIT, 0), s.2)));
    }
    // A miss that can neither merge nor take a place waits for the next fill and asks again
    // (at once when no fill is on its way: it waits for a line in the table to be hit).
    let retry_at = pending.eq(0).select(done, next_fill);
    let wait = found.select(found_seq, alloc.select(new_seq, retry_at)).name(&nm("wait_c"));
    let a_valid = b.valid_delay(&nm("a_valid"), l3_valid);
    let a_hit = b.delay(&nm("a_hit"), hit);
    let a_data: Vec<S<'b>> = data.iter().enumerate().map(|(j, &d)| b.delay(&nm(&format!("a_data{j}")), d)).collect();
    let a_wait = b.delay(&nm("a_wait"), wait);
    let req_valid = b.valid_delay(&nm("req_valid"), alloc);
    let req_line = b.delay(&nm("req_line"), l3_line);
    b.end_stage();
    Cache {
        answer: Answer { valid: a_valid, hit: a_hit, data: a_data, wait: a_wait },
        request: (req_valid, req_line),
        done,
    }
}

/// A record RAM's write enable for way `way` as a register of its own, computed a clock early
/// from the fill's next valid and the record counters' next values, when a record takes two
/// beats or more (`None`: one beat). The enable of a block RAM module fans out to its DP16KDs,
/// spread over the die: from the fill's valid register through an AND it cost 11.1 ns at a
/// seed of the teapot-fine external core. Equal to `write_rec ∧ fill_way = way` every clock:
/// the fill's way changes only at a fill's last beat (then the next beat is a line's first,
/// which ends no record of two beats) or when no fill is in flight (no beat next clock).
fn early_write_enable<'b>(
    b: &'b Builder,
    name: &str,
    p: &CacheParams,
    fill: &Fill<'b>,
    [in_rec_next, rec_no_next]: [S<'b>; 2],
    f_way: S<'b>,
    way: u32,
) -> Option<S<'b>> {
    (p.record_beats >= 2).then(|| {
        let ends = (fill.valid_next
            & in_rec_next.eq((p.record_beats - 1) as i128)
            & rec_no_next.lt(p.records_per_line as i128)
            & f_way.eq(way as i128))
        .name(&format!("{name}_c"));
        b.valid_delay(name, ends)
    })
}

/// A record RAM of the cache: the word at `raddr` two clocks later. When a record takes two
/// beats or more it is a block RAM module (`brom::bram`, whose second register the ECP5 flow
/// makes the DP16KD's own output register: a DP16KD without it gives its data 5.8 ns after the
/// clock, and the cache's record registers were the slowest paths of the teapot-fine core).
/// A DP16KD's read of the word its other port writes in the same clock is not defined, and
/// then no lookup uses it: the line's tag was written invalid at its first beat, which writes
/// no record. A record of one beat is written at the first beat, while a lookup may still read
/// the victim's tag valid, so it stays a RAM that yosys maps with the read-first behaviour the
/// simulators give.
#[allow(clippy::too_many_arguments)]
fn record_ram<'b>(
    b: &'b Builder,
    name: &str,
    p: &CacheParams,
    words: usize,
    we: S<'b>,
    waddr: S<'b>,
    wdata: S<'b>,
    raddr: S<'b>,
) -> S<'b> {
    let width = wdata.width();
    if p.record_beats >= 2 {
        let shape = format!("cache_w{width}_d{words}");
        return super::brom::bram(b, &format!("u_{name}"), &shape, width, words, we, waddr, wdata, raddr);
    }
    let ram = b.ram(name, width, vec![0; words]);
    b.ram_write(ram, we, waddr, wdata);
    let q = b.read(&format!("{name}_q"), ram, raddr);
    b.delay(&format!("{name}_r"), q)
}

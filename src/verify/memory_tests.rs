//! The read master and two caches against the memory model, in the Rust simulator: random
//! lookups (hits, misses, misses to lines on their way, evictions in tiny caches), each answered
//! `cache::LATENCY` clocks later; a hit must carry the image's record, a miss must be released by a fill
//! and hit when asked again; no line is asked for twice while on its way; a broken memory is
//! flagged. `harness` and `drive` also give the transcript tests/memory.rs replays in the HDL
//! simulators. Checks shown failing on their defects: a merge turned off (a line asked for
//! twice), a waiter given the wrong fill number (never released), a lost beat (flagged), a
//! fill asked for the clock the only one pending ends written to the wrong line (a wrong
//! record: the phases of two lookups outstanding make that clock happen).

use super::memory::{MasterOut, MemoryModel, MemoryTiming, xorshift32};
use super::testbench::Stimulus;
use crate::cores::axi_read::{AxiIn, AxiReadParams, LineRequest, axi_read};
use crate::cores::cache::{CacheParams, LATENCY, Lookup, cache};
use crate::rtl::Ty;
use crate::rtl::build::Builder;
use crate::rtl::netlist::Module;
use crate::rtl::sim::Sim;
use std::collections::HashMap;

pub const LINE: u64 = 128;
const ADDR_BITS: u32 = 20;

/// The harness's shape: the read port's data width, the caches' ways, bursts in flight.
#[derive(Clone, Copy, Debug)]
pub struct Shape {
    pub data_bits: u32,
    pub ways: u32,
    pub outstanding: u32,
}

impl Shape {
    /// The two caches: node-like (76-bit records in 16 bytes) and triangle-like (297-bit
    /// records in whole beats: 40 bytes at 32 and 64 bits, 48 at 128), each tiny (8 lines in
    /// sets × ways) over a region of 64 or 32 lines, so lines are evicted all the time. With
    /// (region offset, record bytes).
    pub fn caches(&self) -> [(CacheParams, u64, u32); 2] {
        let beat = self.data_bits / 8;
        let node = CacheParams {
            record_bits: 76,
            record_beats: 16 / beat,
            records_per_line: 8,
            line_beats: LINE as u32 / beat,
            data_bits: self.data_bits,
            sets: 8 / self.ways,
            ways: self.ways,
            line_bits: 6,
            inflight: 4,
        };
        let tri_bytes = 297u32.div_ceil(self.data_bits) * beat;
        let tri = CacheParams {
            record_bits: 297,
            record_beats: tri_bytes / beat,
            records_per_line: LINE as u32 / tri_bytes,
            line_bits: 5,
            ..node
        };
        [(node, LINE, 16), (tri, LINE + 64 * LINE, tri_bytes)]
    }
}

pub fn harness(shape: Shape) -> Module {
    let ap = AxiReadParams {
        addr_bits: ADDR_BITS,
        data_bits: shape.data_bits,
        line_beats: LINE as u32 * 8 / shape.data_bits,
        outstanding: shape.outstanding,
        queue: 4,
    };
    let caches: Vec<(CacheParams, u64)> = shape.caches().iter().map(|&(p, region, _)| (p, region)).collect();
    mem_side("mem_harness", &ap, &caches)
}

/// The read master and caches (each with the byte offset of its region of the image) as one
/// module with the bus, the base address and every cache's lookup as inputs, and every answer,
/// `done` counter and the master's outputs as outputs: `look{c}_valid/_line/_rec`,
/// `ans{c}_valid/_hit/_wait/_data{j}`, `done{c}`, `arvalid`, `araddr`, `arlen`, `error`.
pub fn mem_side(name: &str, ap: &AxiReadParams, caches: &[(CacheParams, u64)]) -> Module {
    let b = Builder::new(name);
    let base = b.input("base", Ty::u(ap.addr_bits));
    let looks: Vec<Lookup> = caches
        .iter()
        .enumerate()
        .map(|(c, (p, _))| Lookup {
            valid: b.input(&format!("look{c}_valid"), Ty::BIT),
            line: b.input(&format!("look{c}_line"), Ty::u(p.line_bits)),
            rec: b.input(&format!("look{c}_rec"), Ty::u(p.rec_bits())),
            cancel: None,
        })
        .collect();
    let bus = AxiIn {
        arready: b.input("arready", Ty::BIT),
        rvalid: b.input("rvalid", Ty::BIT),
        rdata: b.input("rdata", Ty::u(ap.data_bits)),
        rlast: b.input("rlast", Ty::BIT),
        rresp: b.input("rresp", Ty::u(2)),
    };
    // The caches' requests feed the master, whose fills feed the caches: wires close the loop.
    let req: Vec<_> = (0..caches.len())
        .map(|c| (b.wire(&format!("req{c}_valid"), Ty::BIT), b.wire(&format!("req{c}_offset"), Ty::u(ap.addr_bits))))
        .collect();
    let requests: Vec<LineRequest> = req.iter().map(|&(valid, offset)| LineRequest { valid, offset }).collect();
    let (out, fills) = axi_read(&b, ap, base, &requests, &bus);
    let line_bytes = ap.line_beats * ap.data_bits / 8;
    for (c, (p, region)) in caches.iter().enumerate() {
        let k = cache(&b, &format!("c{c}"), p, &looks[c], &fills[c]);
        b.drive(req[c].0, k.request.0);
        let offset = (k.request.1.resize(ap.addr_bits) << line_bytes.trailing_zeros()) + *region as i128;
        b.drive(req[c].1, offset);
        b.output(&format!("ans{c}_valid"), k.answer.valid);
        b.output(&format!("ans{c}_hit"), k.answer.hit);
        b.output(&format!("ans{c}_wait"), k.answer.wait);
        for (j, d) in k.answer.data.iter().enumerate() {
            b.output(&format!("ans{c}_data{j}"), *d);
        }
        b.output(&format!("done{c}"), k.done);
    }
    b.output("arvalid", out.arvalid);
    b.output("araddr", out.araddr);
    b.output("arlen", out.arlen);
    b.output("error", out.error);
    b.finish()
}

/// A test image: every byte a function of its address.
pub fn image() -> Vec<u8> {
    image_salted(0)
}

/// Another test image for each `salt` (a new scene after a reset).
fn image_salted(salt: u32) -> Vec<u8> {
    (0..(LINE * 100) as u32).map(|k| ((k ^ salt).wrapping_mul(2654435761) >> 13) as u8).collect()
}

/// The record `rec` of `line` in cache `c`'s region, as parts of at most 128 bits.
fn record(img: &[u8], shape: Shape, c: usize, line: u64, rec: u64) -> Vec<u128> {
    let (p, region, rbytes) = shape.caches()[c];
    let at = (region + line * LINE + rec * rbytes as u64) as usize;
    p.parts()
        .iter()
        .scan(0u32, |lsb, &w| {
            let mut v = 0u128;
            for bit in 0..w {
                let a = *lsb + bit;
                v |= (((img[at + (a / 8) as usize] >> (a % 8)) & 1) as u128) << bit;
            }
            *lsb += w;
            Some(v)
        })
        .collect()
}

/// A lookup the driver makes until it hits: line, record, the fill it waits for (None: ready
/// to ask), the clock it began waiting.
type Task = (u64, u64, Option<u16>, u64);

/// What a drive found.
#[derive(Default)]
pub struct Drive {
    pub hits: u64,
    pub misses: u64,
    /// Bursts the master asked for.
    pub bursts: u64,
    pub stimuli: Vec<Stimulus>,
    pub error: bool,
}

/// Runs `clocks` clocks of random lookups; `drop_beat` makes the memory lose that beat
/// (counted from 0) of its answer, a broken memory. Panics on a wrong record, a wrong
/// latency, a line asked for twice while on its way, or a waiter never released.
pub fn drive(m: &Module, shape: Shape, timing: MemoryTiming, clocks: u64, seed: u32, drop_beat: Option<u64>) -> Drive {
    drive_on(&mut Sim::new(m), m, shape, &image(), timing, clocks, seed, drop_beat, None)
}

/// `drive` for `clocks`, then a reset and `clocks` more with another image in memory: every hit
/// after the reset must carry the new image's record (the reset empties the caches). The
/// stimuli of both runs, one after the other.
pub fn drive_across_a_reset(m: &Module, shape: Shape, timing: MemoryTiming, clocks: u64, seed: u32) -> Drive {
    let mut sim = Sim::new(m);
    let mut d = drive_on(&mut sim, m, shape, &image(), timing, clocks, seed, None, None);
    let e = drive_on(&mut sim, m, shape, &image_salted(0x5a5a), timing, clocks, seed, None, None);
    d.hits += e.hits;
    d.misses += e.misses;
    d.bursts += e.bursts;
    d.stimuli.extend(e.stimuli);
    d.error |= e.error;
    d
}

/// A clock count after which a waiter for its own line's fill looks again in a duel (`drive_on`).
const SLOW: u64 = 300;

/// `drive` on a simulation that may have run before (its first clock is a reset), with the
/// image `img` in memory. A `duel` of two lines (in one set) replaces the random lookups: each
/// cache is asked for record 0 of both lines, again after every hit, and a task whose miss
/// asked for its own line looks again only `SLOW` clocks after the miss while the other looks
/// as soon as released — the schedule under which each fill's first beat evicts the other
/// line before its waiter comes back, unless the cache keeps a line until its first hit.
#[allow(clippy::too_many_arguments)]
fn drive_on(
    sim: &mut Sim,
    m: &Module,
    shape: Shape,
    img: &[u8],
    timing: MemoryTiming,
    clocks: u64,
    seed: u32,
    drop_beat: Option<u64>,
    duel: Option<[u64; 2]>,
) -> Drive {
    let base = 0x4000u64;
    let mut mem = MemoryModel::new(img.to_vec(), base, shape.data_bits, timing);
    let input = |name: &str| m.handle(*m.inputs.iter().find(|&&i| m.sig(i).name == name).unwrap());
    let output = |name: &str| m.handle(m.outputs.iter().find(|o| o.0 == name).unwrap().1);
    let names: Vec<String> = m.inputs.iter().map(|&i| m.sig(i).name.clone()).collect();
    let mut d = Drive::default();
    let mut x = seed | 1;
    // Per cache: lookups to make, each (line, record, the fill it waits for, since when).
    let mut tasks: Vec<Vec<Task>> = vec![Vec::new(), Vec::new()];
    let mut in_pipe: Vec<Vec<(u64, usize)>> = vec![Vec::new(), Vec::new()];
    let mut on_way: HashMap<u64, u64> = HashMap::new(); // line address → clock asked
    let mut ar_order = std::collections::VecDeque::new();
    // Misses as answered — (cache, fill number, line, fills done then) — and each cache's
    // bursts in the order asked: fill k of cache c is its k-th burst.
    let mut claims = Vec::new();
    let mut asked: [Vec<u64>; 2] = [Vec::new(), Vec::new()];
    let mut beats_seen = 0u64;
    for clock in 0..clocks {
        let mut inputs: HashMap<&str, i128> = HashMap::new();
        for c in 0..2 {
            let (p, _, _) = shape.caches()[c];
            let done = sim.get(output(&format!("done{c}"))) as u16;
            // Answers due now.
            if let Some(&(at, t)) = in_pipe[c].first()
                && at + LATENCY as u64 == clock
            {
                in_pipe[c].remove(0);
                assert_eq!(sim.get(output(&format!("ans{c}_valid"))), 1, "cache {c}: answer at clock {clock}");
                let (line, rec, _, _) = tasks[c][t];
                if sim.get(output(&format!("ans{c}_hit"))) == 1 {
                    let got: Vec<u128> = (0..p.parts().len())
                        .map(|j| sim.get(output(&format!("ans{c}_data{j}"))) as u128 & Ty::u(p.parts()[j]).mask())
                        .collect();
                    if drop_beat.is_none() {
                        assert_eq!(
                            got,
                            record(img, shape, c, line, rec),
                            "cache {c}: line {line} record {rec} at clock {clock}"
                        );
                    }
                    d.hits += 1;
                    tasks[c].swap_remove(t);
                    for e in in_pipe[c].iter_mut() {
                        if e.1 == tasks[c].len() {
                            e.1 = t;
                        }
                    }
                } else {
                    let k = sim.get(output(&format!("ans{c}_wait"))) as u16;
                    d.misses += 1;
                    claims.push((c, k, line, done));
                    tasks[c][t].2 = Some(k);
                    tasks[c][t].3 = clock;
                }
            } else {
                assert_eq!(sim.get(output(&format!("ans{c}_valid"))), 0, "cache {c}: no answer due at clock {clock}");
            }
            // The last 3,000 clocks only finish what was asked: every waiter must be released.
            // Phases of 6 lookups outstanding (the table full) and of 2 (fills one at a time,
            // a new one asked for as the last ends).
            let outstanding = if (clock / 1_500) % 2 == 0 { 6 } else { 2 };
            while let Some(lines) = duel
                && tasks[c].len() < 2
                && clock + 3_000 < clocks
            {
                let line = lines[(tasks[c].first().is_some_and(|t| t.0 == lines[0])) as usize];
                tasks[c].push((line, 0, None, clock));
            }
            while duel.is_none() && tasks[c].len() < outstanding && clock + 3_000 < clocks {
                x = xorshift32(x);
                tasks[c].push((
                    (x >> 4) as u64 % (1 << p.line_bits),
                    (x >> 20) as u64 % p.records_per_line as u64,
                    None,
                    clock,
                ));
            }
            // One lookup: the first task that is ready or released and not in the pipeline.
            x = xorshift32(x);
            let pick = (0..tasks[c].len()).find(|&t| {
                !in_pipe[c].iter().any(|e| e.1 == t)
                    && match tasks[c][t].2 {
                        None => true,
                        Some(k) => {
                            let own = asked[c].get((k as usize).wrapping_sub(1)) == Some(&tasks[c][t].0);
                            (done.wrapping_sub(k) as i16) >= 0
                                && (duel.is_none() || !own || clock >= tasks[c][t].3 + SLOW)
                        }
                    }
            });
            for (t, task) in tasks[c].iter().enumerate() {
                if let Some(k) = task.2 {
                    assert!(
                        clock - task.3 < 20_000,
                        "cache {c}: task {t} waits for fill {k} since {} (done {done})",
                        task.3
                    );
                }
            }
            let (valid, line, rec) = match pick {
                Some(t) if (x & 3 != 0 || duel.is_some()) && clock > 0 => {
                    in_pipe[c].push((clock, t));
                    (1, tasks[c][t].0, tasks[c][t].1)
                }
                _ => (0, 0, 0),
            };
            inputs.insert(["look0_valid", "look1_valid"][c], valid);
            inputs.insert(["look0_line", "look1_line"][c], line as i128);
            inputs.insert(["look0_rec", "look1_rec"][c], rec as i128);
        }
        let mo = MasterOut {
            arvalid: sim.get(output("arvalid")) == 1,
            araddr: sim.get(output("araddr")) as u64,
            arlen: sim.get(output("arlen")) as u32,
            rready: true,
        };
        let mut r = mem.out().clone();
        if r.rvalid && drop_beat == Some(beats_seen) {
            r.rvalid = false;
        }
        if mem.out().rvalid && mem.out().rlast {
            let done = ar_order.pop_front().expect("a burst in flight");
            on_way.remove(&done);
        }
        if mo.arvalid && mem.out().arready {
            assert_eq!(mo.arlen as u64, LINE * 8 / shape.data_bits as u64 - 1);
            assert!(
                !on_way.contains_key(&mo.araddr),
                "line {:#x} asked for again while on its way (clock {clock})",
                mo.araddr
            );
            on_way.insert(mo.araddr, clock);
            ar_order.push_back(mo.araddr);
            let regions = shape.caches().map(|k| k.1);
            let c = (mo.araddr - base >= regions[1]) as usize;
            asked[c].push((mo.araddr - base - regions[c]) / LINE);
            d.bursts += 1;
        }
        if mem.out().rvalid {
            beats_seen += 1;
        }
        inputs.insert("base", base as i128);
        inputs.insert("arready", mem.out().arready as i128);
        inputs.insert("rvalid", r.rvalid as i128);
        inputs.insert("rdata", r.rdata as i128);
        inputs.insert("rlast", r.rlast as i128);
        inputs.insert("rresp", 0);
        let st = Stimulus { reset: clock == 0, inputs: names.iter().map(|n| inputs[n.as_str()]).collect() };
        for (name, v) in names.iter().zip(&st.inputs) {
            sim.set(input(name), *v);
        }
        sim.reset = st.reset;
        d.stimuli.push(st);
        mem.clock(&mo);
        sim.tick();
    }
    d.error = sim.get(output("error")) == 1;
    if drop_beat.is_none() {
        // A miss waits for its own line's fill (merged or new), or — every place in flight
        // taken — for the next fill, after which it asks again (`done` is read at the answer,
        // a clock or two after the cache chose).
        for &(c, k, line, done) in &claims {
            let fill_line = asked[c].get(k as usize - 1).copied();
            assert!(
                fill_line == Some(line) || (k <= done.wrapping_add(1) && k + 2 > done),
                "cache {c}: a miss on line {line} told to wait for fill {k} (line {fill_line:?}), {done} done"
            );
        }
        for (c, t) in tasks.iter().enumerate() {
            assert!(t.is_empty(), "cache {c}: {} lookups never answered with a hit (a wake-up lost)", t.len());
        }
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The one-clock reset empties the caches (a new scene may be in memory after it): after
    /// a drive that leaves them full of one image, a reset and a drive over another image hit
    /// only the new image's records. With the tag RAMs' valid bits not swept after the reset,
    /// the first lookups hit the old lines (a wrong record).
    #[test]
    fn a_reset_empties_the_caches() {
        for shape in
            [Shape { data_bits: 64, ways: 2, outstanding: 8 }, Shape { data_bits: 128, ways: 1, outstanding: 2 }]
        {
            let m = harness(shape);
            let timing = MemoryTiming { latency: 20, ..MemoryTiming::default() };
            let d = drive_across_a_reset(&m, shape, timing, 10_000, 3);
            assert!(!d.error && d.hits > 600, "{shape:?}: {} hits", d.hits);
        }
    }

    /// Forward progress (DECISIONS 109, 113): two waiters whose lines share a set of a one-way
    /// cache, scheduled so that each comes back only after the other's fill has begun, still
    /// hit. With a line free to leave as soon as it arrives, neither ever hits (both lookups are
    /// left unanswered by a hit at the end).
    #[test]
    fn two_lines_in_one_set_do_not_evict_each_other_for_ever() {
        let shape = Shape { data_bits: 64, ways: 1, outstanding: 4 };
        let m = harness(shape);
        let timing = MemoryTiming { latency: 20, ..MemoryTiming::default() };
        let d = drive_on(&mut Sim::new(&m), &m, shape, &image(), timing, 30_000, 3, None, Some([3, 11]));
        assert!(d.hits > 100, "{} hits, {} misses", d.hits, d.misses);
    }

    #[test]
    fn lookups_hit_the_image_after_their_fills() {
        let two = Shape { data_bits: 64, ways: 2, outstanding: 8 };
        let m = harness(two);
        for (timing, seed) in [
            (MemoryTiming { latency: 40, ..MemoryTiming::default() }, 3),
            (MemoryTiming { latency: 1, outstanding: 2, ..MemoryTiming::default() }, 5),
            (MemoryTiming { latency: 200, extra_delay: 60, pause_in_256: 100, seed: 9, ..MemoryTiming::default() }, 7),
        ] {
            let d = drive(&m, two, timing, 30_000, seed, None);
            assert!(!d.error, "{timing:?}: the master flagged a protocol error");
            // More misses than bursts: misses to lines on their way were merged.
            let (h, m, b) = (d.hits, d.misses, d.bursts);
            assert!(h > 500 && m > 200 && m > b + 100, "{timing:?}: {h} hits, {m} misses, {b} bursts");
        }
    }

    /// A memory that loses a beat: the master's count and RLAST disagree from there on.
    #[test]
    fn a_lost_beat_is_flagged() {
        let two = Shape { data_bits: 64, ways: 2, outstanding: 8 };
        let m = harness(two);
        assert!(!drive(&m, two, MemoryTiming::default(), 6_000, 3, None).error);
        assert!(drive(&m, two, MemoryTiming::default(), 6_000, 3, Some(37)).error);
    }

    /// Other data widths (records of 1 to 10 beats, lines of 2 or 3 triangle records) and 1 or
    /// 4 ways, one outstanding burst or many.
    #[test]
    fn every_width_and_associativity() {
        for shape in [
            Shape { data_bits: 128, ways: 1, outstanding: 1 },
            Shape { data_bits: 32, ways: 4, outstanding: 16 },
            Shape { data_bits: 128, ways: 4, outstanding: 4 },
        ] {
            let m = harness(shape);
            let d = drive(
                &m,
                shape,
                MemoryTiming { latency: 30, pause_in_256: 50, ..MemoryTiming::default() },
                20_000,
                5,
                None,
            );
            assert!(!d.error && d.hits > 500 && d.misses > 100, "{shape:?}: {} hits, {} misses", d.hits, d.misses);
        }
    }
    /// A block RAM's read of the word its other port writes in the same clock is not defined
    /// (DP16KD), so a lookup whose tag read meets a fill's tag write in its set is a miss
    /// (`cache`'s `tag_clash`). In a one-way cache, line A hit, then line B of the same set
    /// missed and its fill began: a lookup of A hits exactly when its tag is read before the
    /// clock of B's first beat. With the clash not taken as a miss, the read in that clock
    /// is a hit on the victim (the simulators' RAMs read the old word).
    #[test]
    fn a_tag_read_in_the_clock_of_its_sets_fill_is_a_miss() {
        let shape = Shape { data_bits: 64, ways: 1, outstanding: 4 };
        let m = harness(shape);
        let input = |name: &str| m.handle(*m.inputs.iter().find(|&&i| m.sig(i).name == name).unwrap());
        let output = |name: &str| m.handle(m.outputs.iter().find(|o| o.0 == name).unwrap().1);
        let (line_a, line_b, base) = (1, 9, 0x4000u64);
        let mut seen = [false, false];
        for k in 1..40u64 {
            let mut sim = Sim::new(&m);
            let timing = MemoryTiming { latency: 20, ..MemoryTiming::default() };
            let mut mem = MemoryModel::new(image(), base, shape.data_bits, timing);
            // Lookups of cache 0 by clock: A (miss, filled), A (hit), B (miss), A again.
            let (at_b, at_a) = (150, 150 + k);
            let looks = [(20, line_a), (120, line_a), (at_b, line_b), (at_a, line_a)];
            let (mut first_beat, mut hits) = (None, Vec::new());
            for clock in 0..300u64 {
                if let Some(l) = looks.iter().find(|l| l.0 + LATENCY as u64 == clock) {
                    assert_eq!(sim.get(output("ans0_valid")), 1);
                    hits.push((l.0, sim.get(output("ans0_hit")) == 1));
                }
                let mo = MasterOut {
                    arvalid: sim.get(output("arvalid")) == 1,
                    araddr: sim.get(output("araddr")) as u64,
                    arlen: sim.get(output("arlen")) as u32,
                    rready: true,
                };
                let look = looks.iter().find(|l| l.0 == clock);
                let r = mem.out().clone();
                for (name, v) in [
                    ("look0_valid", look.is_some() as i128),
                    ("look0_line", look.map_or(0, |l| l.1) as i128),
                    ("look0_rec", 0),
                    ("look1_valid", 0),
                    ("look1_line", 0),
                    ("look1_rec", 0),
                    ("base", base as i128),
                    ("arready", r.arready as i128),
                    ("rvalid", r.rvalid as i128),
                    ("rdata", r.rdata as i128),
                    ("rlast", r.rlast as i128),
                    ("rresp", 0),
                ] {
                    sim.set(input(name), v);
                }
                sim.reset = clock == 0;
                sim.eval();
                if clock > at_b && first_beat.is_none() && sim.probe("c0_fill_first") == Some(1) {
                    first_beat = Some(clock);
                }
                mem.clock(&mo);
                sim.tick();
            }
            let first_beat = first_beat.expect("B's fill arrived");
            // Answers come LATENCY clocks after their lookup; the last lookup may be pending.
            assert_eq!(&hits[..3], &[(20, false), (120, true), (at_b, false)], "k {k}");
            // A's tag is read at the clock after its lookup (the lookup's input register).
            let read = at_a + 1;
            let hit = hits.iter().find(|h| h.0 == at_a).expect("A answered").1;
            assert_eq!(hit, read < first_beat, "k {k}: A's tag read at {read}, B's first beat at {first_beat}");
            seen[usize::from(read == first_beat)] = true;
        }
        assert!(seen[1], "no lookup's tag read met the first beat");
    }
}

//! A LUT RAM wider than a few LUT-RAM columns, cut into groups of columns: each group is a RAM
//! of its own, read (one clock, `Builder::read`) at a register of its own.
//!
//! Why: on the ECP5 a LUT-RAM cell (`TRELLIS_DPR16X4`) holds 4 bits of 16 words, so a 96-bit
//! RAM of 128 words is 192 cells, and one read-address register fanning out to all of them
//! spans tens of columns. Placed, the default core's slowest paths were such reads: a queue's
//! read pointer through its RAM into the head register (8.03 ns at seed 1, 34 endpoints over
//! 6.67 ns), the leaf stream's slot into the ray RAMs (7.88 ns, 146 endpoints). A group of at
//! most `GROUP_BITS` bits keeps an address register's sinks to a few cells that the placer can
//! pack around it. The words read are the same; only the netlist's cells are grouped.

use crate::rtl::build::{Builder, S};

/// The widest group: four LUT-RAM columns.
pub const GROUP_BITS: u32 = 16;

/// The narrow groups of a spread core's busiest reads (`fifo::narrow_fifo`, the lanes'
/// direction RAMs): two LUT-RAM columns.
pub const NARROW_GROUP_BITS: u32 = 8;

/// The groups' widths, lowest bits first: as many groups of `GROUP_BITS` or fewer bits as the
/// width needs, all but the last a multiple of 4 bits (whole LUT-RAM cells) and as even as that
/// allows.
pub fn group_widths(width: u32) -> Vec<u32> {
    group_widths_of(width, GROUP_BITS)
}

/// `group_widths` with groups of at most `most` bits (a multiple of 4).
pub fn group_widths_of(width: u32, most: u32) -> Vec<u32> {
    assert!(most > 0 && most % 4 == 0, "groups of whole LUT-RAM cells");
    let groups = width.div_ceil(most);
    let each = width.div_ceil(groups).next_multiple_of(4).min(most);
    let mut left = width;
    let mut widths = Vec::new();
    while left > 0 {
        let w = each.min(left);
        widths.push(w);
        left -= w;
    }
    widths
}

/// The RAM: its groups' memories (`Builder::ram`) and widths, lowest bits first.
#[derive(Clone, Debug)]
pub struct WideRam {
    mems: Vec<(usize, u32)>,
}

impl WideRam {
    /// A RAM of `depth` words of `width` bits, all 0 at start; one group keeps the name `name`,
    /// several are `name_g0`, `name_g1`, … from the low bits.
    pub fn new(b: &Builder, name: &str, width: u32, depth: usize) -> WideRam {
        Self::in_groups_of(b, name, width, depth, GROUP_BITS)
    }

    /// `new` with groups of at most `most` bits.
    pub fn in_groups_of(b: &Builder, name: &str, width: u32, depth: usize, most: u32) -> WideRam {
        let widths = group_widths_of(width, most);
        let one = widths.len() == 1;
        let mems = widths
            .iter()
            .enumerate()
            .map(|(g, &w)| {
                let name = if one { name.to_string() } else { format!("{name}_g{g}") };
                (b.ram(&name, w, vec![0; depth]), w)
            })
            .collect();
        WideRam { mems }
    }

    /// The RAM in one group whatever its width: where its write and read have no fan-out to
    /// split (a core that is not spread over the die).
    pub fn whole(b: &Builder, name: &str, width: u32, depth: usize) -> WideRam {
        WideRam { mems: vec![(b.ram(name, width, vec![0; depth]), width)] }
    }

    /// How many groups (so how many read-address registers a read wants).
    pub fn groups(&self) -> usize {
        self.mems.len()
    }

    /// Writes `data` (the RAM's width) at the address when the write enable is 1: group g at
    /// `addrs[g % addrs.len()]` when `wes[g % wes.len()]` (registers of their own per group
    /// split the fan-out as the reads' do).
    pub fn write<'b>(&self, b: &'b Builder, wes: &[S<'b>], addrs: &[S<'b>], data: S<'b>) {
        let mut at = 0;
        for (g, &(mem, w)) in self.mems.iter().enumerate() {
            b.ram_write(mem, wes[g % wes.len()], addrs[g % addrs.len()], data.slice(at, w));
            at += w;
        }
    }

    /// The word at the address, one clock later, in registers `name` (`name_g0`, … for several
    /// groups): group g read at `addrs[g % addrs.len()]`, so with one register per group each
    /// address register drives one group's cells.
    pub fn read<'b>(&self, b: &'b Builder, name: &str, addrs: &[S<'b>]) -> S<'b> {
        if let [(mem, _)] = self.mems[..] {
            return b.read(name, mem, addrs[0]);
        }
        let words: Vec<S<'b>> = self
            .mems
            .iter()
            .enumerate()
            .rev()
            .map(|(g, &(mem, _))| b.read(&format!("{name}_g{g}"), mem, addrs[g % addrs.len()]))
            .collect();
        b.cat(&words).name(name)
    }
}

/// `reg` and copies of it (`Builder::copies`): `count` registers in all, one per group of a
/// RAM it addresses.
pub fn address_registers<'b>(b: &'b Builder, reg: S<'b>, count: usize) -> Vec<S<'b>> {
    let mut regs = vec![reg];
    if count > 1 {
        regs.extend(b.copies(reg, count - 1));
    }
    regs
}

/// `items` dealt out in turn as runs of `counts` items, wrapping around when there are fewer:
/// a RAM's groups' registers from a list of copies for several RAMs.
pub fn runs<T: Copy>(items: &[T], counts: &[usize]) -> Vec<Vec<T>> {
    let mut next = 0;
    counts
        .iter()
        .map(|&count| {
            let run = (next..next + count).map(|k| items[k % items.len()]).collect();
            next += count;
            run
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rtl::Ty;
    use crate::rtl::sim::Sim;

    #[test]
    fn groups_cover_the_width_in_whole_cells_of_at_most_group_bits() {
        for width in 1..=200 {
            let g = group_widths(width);
            assert_eq!(g.iter().sum::<u32>(), width, "{width}");
            assert!(g.iter().all(|&w| w <= GROUP_BITS && w > 0), "{width}: {g:?}");
            assert!(g[..g.len() - 1].iter().all(|&w| w % 4 == 0), "{width}: {g:?}");
            assert_eq!(g.len() as u32, width.div_ceil(GROUP_BITS), "{width}: {g:?}");
        }
        assert_eq!(group_widths(96), vec![16; 6]);
        assert_eq!(group_widths(34), vec![12, 12, 10]);
        assert_eq!(group_widths_of(56, 8), vec![8; 7]);
        assert_eq!(group_widths_of(34, 8), vec![8, 8, 8, 8, 2]);
    }

    /// Words written at random addresses read back whole, each group at its own address
    /// register (all holding the same address), one clock after the address.
    #[test]
    fn reads_back_what_was_written_across_groups() {
        let b = Builder::new("t");
        let we = b.input("we", Ty::BIT);
        let addr = b.input("addr", Ty::u(5));
        let data = b.input("data", Ty::u(87));
        let raddr = b.input("raddr", Ty::u(5));
        let ram = WideRam::new(&b, "mem", 87, 32);
        assert_eq!(ram.groups(), 6);
        ram.write(&b, &[we], &[addr], data);
        let addrs = address_registers(&b, b.delay("raddr_r", raddr), ram.groups());
        b.output("q", ram.read(&b, "q", &addrs));
        let m = b.finish();
        let mut sim = Sim::new(&m);
        let h = |i: usize| m.handle(m.inputs[i]);
        let q = m.handle(m.outputs[0].1);
        let mut x = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        };
        let mask = (1i128 << 87) - 1;
        // Every address written (some twice), then read back in a random order, two clocks
        // from the address at the input to the word at the output.
        let mut model = [0i128; 32];
        for k in 0..64 {
            let (a, d) = (k % 32, ((next() as i128) << 64 | next() as i128) & mask);
            model[a] = d;
            sim.set(h(0), 1);
            sim.set(h(1), a as i128);
            sim.set(h(2), d);
            sim.tick();
        }
        sim.set(h(0), 0);
        let mut asked = Vec::new();
        for cycle in 0..200 {
            let a = (next() % 32) as usize;
            sim.set(h(3), a as i128);
            asked.push(a);
            sim.eval();
            if cycle >= 2 {
                assert_eq!(sim.get(q), model[asked[cycle - 2]], "cycle {cycle}");
            }
            sim.tick();
        }
        assert!(model.iter().filter(|&&v| v >> 80 != 0).count() > 20, "words use the top group");
    }
}

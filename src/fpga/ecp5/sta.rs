//! The slowest paths of a routed design, one per endpoint register group, from the SDF nextpnr
//! writes (`--sdf`). nextpnr's own report names one critical path per clock; closing timing on
//! a core with hundreds of failing endpoints one path per place-and-route run (an hour for the
//! external-memory core) is too slow, so this reads every cell delay (`IOPATH`), every routed
//! net delay (`INTERCONNECT`) and every setup check (`SETUPHOLD`) and finds the longest
//! register-to-register path into each endpoint. Delays are the triples' maximum, as nextpnr's
//! own analysis uses; the worst path found equals nextpnr's critical path (`tests/ecp5.rs`).

use std::collections::BTreeMap;

/// One endpoint group's slowest path: from a register's clock-to-output through the cells in
/// `through` to the setup check at `end`; `delay_ns` includes the clock-to-output and the setup.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SlowPath {
    pub delay_ns: f64,
    pub start: String,
    pub end: String,
    /// The cells between start and end, in order (netlist names: yosys names a LUT after the
    /// signal it makes).
    pub through: Vec<String>,
    /// The cells the path passes through between start and end (LUTs, carry cells, RAM and
    /// multiplier stages): `through` names them once per netlist name.
    pub cells: usize,
    /// How many endpoint pins of this group are slower than `floor_ns` (`slowest_paths`).
    pub endpoints_over: usize,
}

/// An SDF token: a parenthesis or an atom (a quoted string without its quotes, or a word with
/// its escapes removed).
#[derive(Debug, PartialEq)]
enum Tok<'a> {
    Open,
    Close,
    Atom(std::borrow::Cow<'a, str>),
}

fn tokens(text: &str) -> impl Iterator<Item = Tok<'_>> {
    let bytes = text.as_bytes();
    let mut i = 0;
    std::iter::from_fn(move || {
        while i < bytes.len() && bytes[i].is_ascii_whitespace() {
            i += 1;
        }
        let start = i;
        match *bytes.get(i)? {
            b'(' => {
                i += 1;
                Some(Tok::Open)
            }
            b')' => {
                i += 1;
                Some(Tok::Close)
            }
            b'"' => {
                let end = text[i + 1..].find('"').map_or(bytes.len(), |k| i + 1 + k);
                i = (end + 1).min(bytes.len());
                Some(Tok::Atom(text[start + 1..end].into()))
            }
            _ => {
                let mut escaped = false;
                while i < bytes.len() {
                    let c = bytes[i];
                    if c == b'\\' {
                        escaped = true;
                        i += 2;
                        continue;
                    }
                    if c.is_ascii_whitespace() || c == b'(' || c == b')' {
                        break;
                    }
                    i += 1;
                }
                let word = &text[start..i.min(bytes.len())];
                Some(Tok::Atom(if escaped { word.replace('\\', "").into() } else { word.into() }))
            }
        }
    })
}

/// An S-expression of the SDF.
#[derive(Debug)]
enum Sx<'a> {
    Atom(std::borrow::Cow<'a, str>),
    List(Vec<Sx<'a>>),
}

impl<'a> Sx<'a> {
    fn head(&self) -> Option<&str> {
        match self {
            Sx::List(v) => match v.first() {
                Some(Sx::Atom(a)) => Some(a),
                _ => None,
            },
            Sx::Atom(_) => None,
        }
    }

    fn items(&self) -> &[Sx<'a>] {
        match self {
            Sx::List(v) => v,
            Sx::Atom(_) => &[],
        }
    }

    fn atom(&self) -> Option<&str> {
        match self {
            Sx::Atom(a) => Some(a),
            Sx::List(_) => None,
        }
    }

    fn child(&self, head: &str) -> Option<&Sx<'a>> {
        self.items().iter().find(|x| x.head() == Some(head))
    }
}

fn parse(text: &str) -> Result<Sx<'_>, String> {
    let mut stack: Vec<Vec<Sx>> = vec![Vec::new()];
    for t in tokens(text) {
        match t {
            Tok::Open => stack.push(Vec::new()),
            Tok::Close => {
                let list = stack.pop().filter(|_| !stack.is_empty()).ok_or("an unmatched ')'")?;
                stack.last_mut().expect("checked").push(Sx::List(list));
            }
            Tok::Atom(a) => stack.last_mut().expect("never empty").push(Sx::Atom(a)),
        }
    }
    match (stack.len(), stack.pop()) {
        (1, Some(mut top)) if top.len() == 1 => Ok(top.pop().expect("one")),
        _ => Err("unbalanced parentheses or several top-level forms".into()),
    }
}

/// The largest value of a delay like `(430:477:525)` (or `(477)`), in ps.
fn max_ps(x: &Sx) -> Option<f64> {
    let atom = x.items().first()?.atom()?;
    atom.split(':').filter_map(|v| v.parse::<f64>().ok()).reduce(f64::max)
}

/// A port reference `(posedge CLK)` or `CLK`: the port's name.
fn port_name<'s>(x: &'s Sx) -> Option<&'s str> {
    match x {
        Sx::Atom(a) => Some(a),
        Sx::List(v) => v.last()?.atom(),
    }
}

/// The timing graph: nodes are `instance/port` pins.
#[derive(Default)]
struct Graph {
    ids: BTreeMap<String, u32>,
    names: Vec<String>,
    /// Combinational edges (to, from, delay ps): net delays and cell arcs from a data input.
    edges: Vec<(u32, u32, f64)>,
    /// Clock-to-output arcs: the output pin and its delay.
    launch: Vec<(u32, f64)>,
    /// Setup checks: the data pin and its setup time.
    capture: Vec<(u32, f64)>,
}

impl Graph {
    fn pin(&mut self, inst: &str, port: &str) -> u32 {
        let name = if inst.is_empty() { port.to_string() } else { format!("{inst}/{port}") };
        if let Some(&id) = self.ids.get(&name) {
            return id;
        }
        let id = self.names.len() as u32;
        self.names.push(name.clone());
        self.ids.insert(name, id);
        id
    }

    fn cell(&mut self, cell: &Sx) {
        let inst = cell.child("INSTANCE").and_then(|i| i.items().get(1)).and_then(|a| a.atom()).unwrap_or("");
        let inst = inst.to_string();
        // A cell's clock pins: those its setup checks are taken against.
        let mut clocks: Vec<String> = Vec::new();
        let mut checks = Vec::new();
        for tc in cell.items().iter().filter(|x| x.head() == Some("TIMINGCHECK")) {
            for check in tc.items().iter().skip(1) {
                let it = check.items();
                if !matches!(check.head(), Some("SETUPHOLD" | "SETUP")) || it.len() < 4 {
                    continue;
                }
                let (Some(data), Some(clock), Some(setup)) = (port_name(&it[1]), port_name(&it[2]), max_ps(&it[3]))
                else {
                    continue;
                };
                clocks.push(clock.to_string());
                checks.push((data.to_string(), setup));
            }
        }
        for (data, setup) in checks {
            let p = self.pin(&inst, &data);
            self.capture.push((p, setup));
        }
        let is_clock = |p: &str| clocks.iter().any(|c| c == p) || p.starts_with("CLK") || p == "WCK";
        for delay in cell.items().iter().filter(|x| x.head() == Some("DELAY")) {
            for abs in delay.items().iter().filter(|x| x.head() == Some("ABSOLUTE")) {
                for arc in abs.items().iter().skip(1) {
                    let it = arc.items();
                    let ps = || it[3..].iter().filter_map(max_ps).reduce(f64::max);
                    match (arc.head(), it.len()) {
                        (Some("IOPATH"), 4..) => {
                            let (Some(a), Some(z), Some(d)) = (port_name(&it[1]), port_name(&it[2]), ps()) else {
                                continue;
                            };
                            let to = self.pin(&inst, z);
                            if is_clock(a) {
                                self.launch.push((to, d));
                            } else {
                                let from = self.pin(&inst, a);
                                self.edges.push((to, from, d));
                            }
                        }
                        (Some("INTERCONNECT"), 4..) => {
                            let (Some(a), Some(z), Some(d)) = (it[1].atom(), it[2].atom(), ps()) else { continue };
                            let (from, to) = (self.pin("", a), self.pin("", z));
                            self.edges.push((to, from, d));
                        }
                        _ => {}
                    }
                }
            }
        }
    }
}

/// The instance of pin `name` (`instance/port`).
fn instance(name: &str) -> &str {
    name.rsplit_once('/').map_or(name, |(i, _)| i)
}

/// The netlist's own name of a cell (yosys's mapping suffixes cut, `super::ours`), or the
/// cell's name where the tools made it up.
fn netlist_name(inst: &str) -> String {
    let ours = super::ours(inst);
    if ours.is_empty() { inst.to_string() } else { ours }
}

/// An endpoint's group: the register (or RAM, multiplier) it belongs to in the netlist, so a
/// 64-bit register's worst bit stands for it.
fn group(name: &str) -> String {
    netlist_name(instance(name))
}

/// The `count` slowest endpoint groups of the routed design in `sdf` (nextpnr's `--sdf`), each
/// with its slowest path and how many of its endpoint pins are slower than `floor_ns`.
pub fn slowest_paths(sdf: &str, count: usize, floor_ns: f64) -> Result<Slowest, String> {
    let top = parse(sdf)?;
    let mut g = Graph::default();
    for cell in top.items().iter().filter(|x| x.head() == Some("CELL")) {
        g.cell(cell);
    }
    let n = g.names.len();
    // Longest arrival times in topological order of the combinational edges.
    let mut fanin: Vec<Vec<(u32, f64)>> = vec![Vec::new(); n];
    let mut fanout: Vec<Vec<u32>> = vec![Vec::new(); n];
    for &(to, from, d) in &g.edges {
        fanin[to as usize].push((from, d));
        fanout[from as usize].push(to);
    }
    let mut arrival = vec![f64::NEG_INFINITY; n];
    let mut pred: Vec<Option<u32>> = vec![None; n];
    for &(p, d) in &g.launch {
        arrival[p as usize] = arrival[p as usize].max(d);
    }
    let mut waiting: Vec<usize> = fanin.iter().map(Vec::len).collect();
    let mut ready: Vec<u32> = (0..n as u32).filter(|&p| waiting[p as usize] == 0).collect();
    let mut done = 0;
    while let Some(p) = ready.pop() {
        done += 1;
        for &(from, d) in &fanin[p as usize] {
            let a = arrival[from as usize] + d;
            if a > arrival[p as usize] {
                arrival[p as usize] = a;
                pred[p as usize] = Some(from);
            }
        }
        for &to in &fanout[p as usize] {
            waiting[to as usize] -= 1;
            if waiting[to as usize] == 0 {
                ready.push(to);
            }
        }
    }
    if done < n {
        return Err(format!("a combinational loop through {} pins", n - done));
    }
    let mut groups: BTreeMap<String, SlowPath> = BTreeMap::new();
    for &(p, setup) in &g.capture {
        if !arrival[p as usize].is_finite() {
            continue;
        }
        let delay_ns = (arrival[p as usize] + setup) / 1000.0;
        let name = &g.names[p as usize];
        let entry = groups.entry(group(name)).or_insert_with(|| SlowPath {
            delay_ns: f64::NEG_INFINITY,
            start: String::new(),
            end: String::new(),
            through: Vec::new(),
            cells: 0,
            endpoints_over: 0,
        });
        entry.endpoints_over += usize::from(delay_ns > floor_ns);
        if delay_ns > entry.delay_ns {
            let mut cells: Vec<String> = Vec::new();
            let mut raw: Vec<&str> = Vec::new();
            let mut at = p;
            while let Some(prev) = pred[at as usize] {
                let inst = instance(&g.names[prev as usize]);
                if raw.last() != Some(&inst) {
                    raw.push(inst);
                }
                let cell = netlist_name(inst);
                if cells.last() != Some(&cell) {
                    cells.push(cell);
                }
                at = prev;
            }
            cells.reverse();
            let start = cells.first().cloned().unwrap_or_default();
            let end = group(name);
            let through = cells.into_iter().skip(1).filter(|c| *c != end).collect();
            let cells = raw.len().saturating_sub(1);
            *entry = SlowPath { delay_ns, start, end, through, cells, endpoints_over: entry.endpoints_over };
        }
    }
    let mut paths: Vec<SlowPath> = groups.into_values().collect();
    paths.sort_by(|a, b| b.delay_ns.total_cmp(&a.delay_ns).then_with(|| a.end.cmp(&b.end)));
    let over = paths.iter().filter(|p| p.delay_ns > floor_ns);
    let (groups_over, endpoints_over) = (over.clone().count(), over.map(|p| p.endpoints_over).sum());
    paths.truncate(count);
    for p in &mut paths {
        p.delay_ns = (p.delay_ns * 1000.0).round() / 1000.0;
    }
    Ok(Slowest { paths, groups_over, endpoints_over })
}

/// `slowest_paths`' answer: the slowest `count` endpoint groups, and how many groups and
/// endpoint pins in all are slower than the floor (the work left to close timing, which the
/// list's length hides).
#[derive(Clone, Debug, PartialEq)]
pub struct Slowest {
    pub paths: Vec<SlowPath>,
    pub groups_over: usize,
    pub endpoints_over: usize,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two registers a → LUT → b, and b → b: the path into b is the clock-to-output, the net,
    /// the LUT, the net and b's setup; a register only launched from counts for nothing.
    #[test]
    fn a_path_sums_its_cell_and_net_delays() {
        let sdf = r#"(DELAYFILE (SDFVERSION "3.0") (TIMESCALE 1ps)
          (CELL (CELLTYPE "top") (INSTANCE )
            (DELAY (ABSOLUTE
              (INTERCONNECT a_ff/Q lut\[1\]/A (100:150:200) (100:150:200))
              (INTERCONNECT lut\[1\]/F b_ff_3/DI (50:60:70) (50:60:70)))))
          (CELL (CELLTYPE "TRELLIS_FF") (INSTANCE a_ff)
            (DELAY (ABSOLUTE (IOPATH CLK Q (400:450:500) (400:450:500)))))
          (CELL (CELLTYPE "TRELLIS_COMB") (INSTANCE lut\[1\])
            (DELAY (ABSOLUTE (IOPATH A F (200:210:220) (200:230:240)))))
          (CELL (CELLTYPE "TRELLIS_FF") (INSTANCE b_ff_3)
            (DELAY (ABSOLUTE (IOPATH CLK Q (400:450:500) (400:450:500))))
            (TIMINGCHECK (SETUPHOLD (posedge DI) (posedge CLK) (30:40:50) (0:0:0)))))"#;
        let slowest = slowest_paths(sdf, 5, 0.5).unwrap();
        let paths = &slowest.paths;
        assert_eq!(paths.len(), 1);
        let p = &paths[0];
        // 500 + 200 + 240 + 70 + 50 ps.
        assert_eq!(p.delay_ns, 1.06);
        assert_eq!((p.start.as_str(), p.end.as_str()), ("a_ff", "b_ff_3"));
        assert_eq!(p.through, vec!["lut[1]".to_string()]);
        assert_eq!(p.cells, 1);
        assert_eq!(p.endpoints_over, 1);
        assert_eq!(group("u.x_TRELLIS_FF_Q_12/DI"), "u.x");
        // The counts cover every group over the floor, listed or not, and only those.
        let unlisted = slowest_paths(sdf, 0, 0.5).unwrap();
        assert_eq!((unlisted.paths.len(), unlisted.groups_over, unlisted.endpoints_over), (0, 1, 1));
        let fast = slowest_paths(sdf, 5, 2.0).unwrap();
        assert_eq!((fast.paths.len(), fast.groups_over, fast.endpoints_over), (1, 0, 0));
    }

    #[test]
    fn a_loop_or_broken_file_is_an_error() {
        assert!(slowest_paths("(DELAYFILE (CELL)", 1, 0.0).is_err());
        let looped = r#"(DELAYFILE (CELL (CELLTYPE "top") (INSTANCE )
            (DELAY (ABSOLUTE (INTERCONNECT x/F y/A (1) (1)) (INTERCONNECT y/F x/A (1) (1)))))
            (CELL (CELLTYPE "C") (INSTANCE x) (DELAY (ABSOLUTE (IOPATH A F (1) (1)))))
            (CELL (CELLTYPE "C") (INSTANCE y) (DELAY (ABSOLUTE (IOPATH A F (1) (1))))))"#;
        assert!(slowest_paths(looped, 1, 0.0).unwrap_err().contains("loop"));
    }
}

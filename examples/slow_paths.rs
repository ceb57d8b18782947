//! The slowest endpoint groups of a routed ECP5 design from nextpnr's SDF (`--sdf`):
//! `cargo run --release --example slow_paths -- design.sdf [COUNT [FLOOR_NS]]` prints them as
//! JSON, slowest first, each with how many of its endpoint pins are slower than FLOOR_NS, and on
//! stderr how many groups and pins in all are slower than FLOOR_NS.

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let Some(path) = args.get(1) else {
        eprintln!("usage: slow_paths design.sdf [count [floor_ns]]");
        std::process::exit(2);
    };
    let count = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(20);
    let floor = args.get(3).and_then(|a| a.parse().ok()).unwrap_or(10.0);
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| {
        eprintln!("{path}: {e}");
        std::process::exit(2);
    });
    match fxrt::fpga::ecp5::sta::slowest_paths(&text, count, floor) {
        Ok(slowest) => {
            println!("{}", serde_json::to_string_pretty(&slowest.paths).expect("serialisable"));
            eprintln!(
                "{} endpoint groups ({} endpoint pins) slower than {floor} ns",
                slowest.groups_over, slowest.endpoints_over
            );
        }
        Err(e) => {
            eprintln!("{path}: {e}");
            std::process::exit(2);
        }
    }
}

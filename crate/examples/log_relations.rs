//! Relation errors (Kümmerle et al. 2009) of the log SLAM on the real logs
//! of `../shared/data/carmen` (BENCHMARKS.md, "Real laser logs").
//!
//! `cargo run --release -p slamlab --example log_relations [LOG ...]`
//!
//! Without arguments: the raw MIT CSAIL log against GMapping's poses, then
//! each corrected log with drifting odometry against its own poses.

#[path = "../../tests/real_support/mod.rs"]
mod support;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let all = [
        "mit-csail.clf.gz",
        "intel-corrected.log.gz",
        "aces-corrected.log.gz",
        "csail-corrected.log.gz",
        "freiburg-079-corrected.log.gz",
    ];
    let names: Vec<&str> = if args.is_empty() {
        all.to_vec()
    } else {
        args.iter().map(|s| s.as_str()).collect()
    };
    for name in names {
        if name == "mit-csail.clf.gz" {
            let (o, recorded) = support::csail_raw();
            print!("{}", support::table(name, &o));
            println!(
                "  recorded {recorded:.0} s, replayed {:.2} s: {:.0}x faster",
                o.seconds,
                recorded / o.seconds
            );
        } else {
            let o = support::corrected(name);
            print!("{}", support::table(name, &o));
        }
    }
}

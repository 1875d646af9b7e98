//! Relation errors (Kümmerle et al. 2009) of the log SLAM on the real logs
//! of `../shared/data/carmen` (BENCHMARKS.md, "Log replay").
//!
//! `cargo run --release -p slamlab --example log_relations [LOG ...]`
//!
//! Without arguments: the raw MIT CSAIL log against GMapping's poses, then
//! each corrected log with drifting odometry against its own poses.
//!
//! `SLAMLAB_LOG_SLAM="key_sigma_m=0.1,loop_every=1"` changes settings of
//! `LogSlamConfig` for an experiment (the names in `tests/real_support`); the figures in
//! BENCHMARKS.md use the defaults unless they say otherwise.

#[path = "../../tests/real_support/mod.rs"]
mod support;

fn main() {
    let cfg = support::config_from_env();
    for name in support::logs_from_args() {
        let name = name.as_str();
        if name == "mit-csail.clf.gz" {
            let (o, recorded) = support::csail_raw_with(&cfg);
            print!("{}", support::table(name, &o));
            println!(
                "  recorded {recorded:.0} s, replayed {:.2} s: {:.0}x faster",
                o.seconds,
                recorded / o.seconds
            );
        } else {
            let o = support::corrected_with(name, &cfg);
            print!("{}", support::table(name, &o));
        }
    }
}

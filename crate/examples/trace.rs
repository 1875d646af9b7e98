//! Prints what each robot is doing over a time window: the follower's mode,
//! the true pose and the command. Useful to see how an encounter or a corner
//! plays out.
//!
//! `cargo run --release -p slamlab --example trace -- scenarios/thesis.json 60 100`

use slamlab::lab::Lab;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let usage = "usage: trace SCENARIO.json FROM_S TO_S";
    let text = std::fs::read_to_string(args.get(1).ok_or(usage)?)?;
    let from: f64 = args.get(2).ok_or(usage)?.parse()?;
    let to: f64 = args.get(3).ok_or(usage)?.parse()?;
    let mut lab = Lab::new(&text)?;
    while lab.state().time_s < to && !lab.state().finished {
        lab.step(5)?;
        let st = lab.state();
        if st.time_s >= from {
            let robots: Vec<String> = st
                .robots
                .iter()
                .map(|r| {
                    format!(
                        "{:7} ({:5.2},{:5.2},{:6.1}) v{:5.2} w{:5.2}",
                        r.mode,
                        r.truth[0],
                        r.truth[1],
                        r.truth[2].to_degrees(),
                        r.v_mps,
                        r.omega_radps
                    )
                })
                .collect();
            println!("{:6.1} {}", st.time_s, robots.join(" | "));
        }
    }
    Ok(())
}

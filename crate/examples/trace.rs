use slamlab::lab::Lab;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let text = std::fs::read_to_string(&args[1]).unwrap();
    let from: f64 = args[2].parse().unwrap();
    let to: f64 = args[3].parse().unwrap();
    let mut lab = Lab::new(&text).unwrap();
    while lab.state().time_s < to {
        lab.step(5).unwrap();
        let st = lab.state();
        if st.time_s >= from {
            let s: Vec<String> = st
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
            println!("{:6.1} {}", st.time_s, s.join(" | "));
        }
    }
}

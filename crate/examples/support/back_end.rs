//! The loop-closing back end in the SLAM experiments (`slam_trace`,
//! `sim_drift`): its settings from the environment, and its loop closures
//! scored against the truth (read here only, to score).

use slamlab::geom::wrap_angle;
use slamlab::sim::RobotSim;
use slamlab::slam::mapper::RobotMapping;
use slamlab::slam::robot_graph::RobotGraphConfig;

/// The back end's settings with those named in the environment overridden:
/// `GRAPH_MIN_SCORE`, `GRAPH_MIN_CONSTRAINT`, `GRAPH_RADIUS_M`,
/// `GRAPH_WINDOW_M`, `GRAPH_DRIFT_PER_M`, `GRAPH_CLOSURE_SIGMA_M`,
/// `GRAPH_CLOSURE_SIGMA_DEG`, `GRAPH_REFINE_MIN_POINTS`,
/// `GRAPH_CLOSURE_MAX_WEAK_M`, `GRAPH_CONFIRM_M`, `GRAPH_CONFIRM_DEG`,
/// `GRAPH_FLOOR_M`, `GRAPH_FLOOR_DEG`, `GRAPH_LOOP_EVERY`,
/// `GRAPH_SATISFIED_M`, `GRAPH_COOLDOWN`; `GRAPH_MANHATTAN_DEG` (the square
/// walls' prior's σ; 0: off), `GRAPH_MANHATTAN_ANCHOR`, `GRAPH_MANHATTAN_EVERY`,
/// `GRAPH_MANHATTAN_LINE_M`, `GRAPH_MANHATTAN_LINE_RMS_M` (its straight walls); `GRAPH_NO_LOOPS` (set) searches
/// no closure, `GRAPH_TRIALS` (set) records every closure found.
pub fn config_from_env(c: &mut RobotGraphConfig) {
    let env = |k: &str| std::env::var(k).ok().and_then(|v| v.parse::<f64>().ok());
    let deg = |k: &str, v: &mut f64| *v = env(k).map_or(*v, f64::to_radians);
    let count = |k: &str, v: &mut usize| *v = env(k).map_or(*v, |x| x as usize);
    let num = |k: &str, v: &mut f64| *v = env(k).unwrap_or(*v);
    if let Ok(v) = std::env::var("GRAPH_MANHATTAN_DEG") {
        let sigma: f64 = v.parse().expect("GRAPH_MANHATTAN_DEG");
        c.manhattan = (sigma > 0.0).then(|| slamlab::slam::manhattan::ManhattanConfig {
            sigma_rad: sigma.to_radians(),
            ..Default::default()
        });
    }
    if let Some(m) = &mut c.manhattan {
        num("GRAPH_MANHATTAN_LINE_M", &mut m.line_min_m);
        num("GRAPH_MANHATTAN_LINE_RMS_M", &mut m.line_max_rms_m);
    }
    if let Ok(v) = std::env::var("GRAPH_MANHATTAN_ANCHOR") {
        c.manhattan_anchor_keys = v.parse().expect("GRAPH_MANHATTAN_ANCHOR");
    }
    if let Ok(v) = std::env::var("GRAPH_MANHATTAN_EVERY") {
        c.manhattan_every = v.parse().expect("GRAPH_MANHATTAN_EVERY");
    }
    num("GRAPH_MIN_SCORE", &mut c.loops.min_score);
    num("GRAPH_MIN_CONSTRAINT", &mut c.min_constraint);
    num("GRAPH_RADIUS_M", &mut c.loops.search_radius_m);
    num("GRAPH_WINDOW_M", &mut c.loops.window.linear_m);
    num("GRAPH_DRIFT_PER_M", &mut c.drift_per_metre);
    num("GRAPH_CLOSURE_SIGMA_M", &mut c.loops.sigma_m);
    deg("GRAPH_CLOSURE_SIGMA_DEG", &mut c.loops.sigma_rad);
    count("GRAPH_REFINE_MIN_POINTS", &mut c.refine_min_points);
    num("GRAPH_CLOSURE_MAX_WEAK_M", &mut c.closure_max_weak_m);
    num("GRAPH_CONFIRM_M", &mut c.confirm_m);
    deg("GRAPH_CONFIRM_DEG", &mut c.confirm_rad);
    num("GRAPH_FLOOR_M", &mut c.floor_m);
    deg("GRAPH_FLOOR_DEG", &mut c.floor_rad);
    count("GRAPH_LOOP_EVERY", &mut c.loop_every);
    num("GRAPH_SATISFIED_M", &mut c.satisfied_m);
    count("GRAPH_COOLDOWN", &mut c.cooldown_keys);
    if std::env::var("GRAPH_NO_LOOPS").is_ok() {
        c.loops.min_key_gap = usize::MAX / 2;
    }
    c.record_trials = std::env::var("GRAPH_TRIALS").is_ok();
}

/// Each accepted closure from the `seen`-th on, with its error against the
/// truth (the relative pose between the two steps' true poses).
pub fn print_accepted(r: &RobotSim, mapping: &RobotMapping, seen: usize) {
    let Some(g) = &mapping.graph else {
        return;
    };
    for c in &g.closures[seen.min(g.closures.len())..] {
        let (a, b) = (r.log.truth[c.from_step], r.log.truth[c.to_step]);
        let e = a.between(&b).between(&c.measurement);
        println!(
            "{:>8} closure keys {}→{} (steps {}→{}) score {:.2}: error {:.3} m {:+.2}°",
            r.spec.name,
            c.from_key,
            c.to_key,
            c.from_step,
            c.to_step,
            c.score,
            e.position().length(),
            wrap_angle(e.theta).to_degrees()
        );
    }
}

/// Every closure the search found (with `record_trials`), with its error
/// against the truth beside what the back end could see of it: the score,
/// the refinement's points on old surfaces, its heading σ and weakest
/// position σ (for 1 cm residuals), the correction asked of the graph, and
/// whether it was accepted.
pub fn print_trials(r: &RobotSim, mapping: &RobotMapping) {
    let Some(g) = &mapping.graph else {
        return;
    };
    for t in &g.trials {
        let (a, b) = (
            r.log.truth[t.closure.from_step],
            r.log.truth[t.closure.to_step],
        );
        let e = a.between(&b).between(&t.closure.measurement);
        let accepted = g
            .closures
            .iter()
            .any(|c| c.from_key == t.closure.from_key && c.to_key == t.closure.to_key);
        let sigma_deg = t.fit.heading_rad.to_degrees();
        println!(
            "{:>8} trial {}→{} score {:.2} on {}/{}{} σθ {:.3}° σw {:.3} corr {:.3} m {:+.2}° path {:.0} m {}{}: error {:.3} m {:+.2}°",
            r.spec.name,
            t.closure.from_key,
            t.closure.to_key,
            t.closure.score,
            t.fit.count,
            t.fit.with_normal,
            if t.refined { "" } else { " (unrefined)" },
            sigma_deg,
            t.fit.weak_m,
            t.correction.position().length(),
            wrap_angle(t.correction.theta).to_degrees(),
            t.path_m,
            if t.plausible { "plausible" } else { "implausible" },
            if accepted { " ACCEPTED" } else { "" },
            e.position().length(),
            wrap_angle(e.theta).to_degrees()
        );
    }
}

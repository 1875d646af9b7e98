//! # The run report
//!
//! `node web/cli.mjs run SCENARIO.json --json` prints this report; its field
//! names are fixed by `shared/docs/interfaces.md` and only ever extended.
//! Trajectories are `[t, x, y, theta]` rows, one per control step, all
//! aligned on the same times: `truth` in the world frame, `odometry` in the
//! robot's own odometry frame (origin at its start pose).
//!
//! Besides the fixed fields, each robot carries the figures a student looks
//! at first: how far it drove, how far its odometry ended from the truth.

use crate::geom::{wrap_angle, Pose2};
use crate::sim::Simulation;
use serde::Serialize;

/// Rounds to micrometres / microradians: enough for any figure we report,
/// and it keeps the JSON a third of the size.
fn r6(x: f64) -> f64 {
    (x * 1e6).round() / 1e6
}

/// A trajectory as `[t, x, y, theta]` rows, written straight from the
/// robot's log when the report is serialised: an hour's run of sixteen
/// robots has 1.7 million such rows, and a copy of them (55 MB) is memory
/// the report need not take.
#[derive(Clone, Copy, Debug)]
pub struct Rows<'a> {
    times: &'a [f64],
    poses: &'a [Pose2],
}

impl<'a> Rows<'a> {
    pub fn new(times: &'a [f64], poses: &'a [Pose2]) -> Rows<'a> {
        Rows { times, poses }
    }

    /// The rows, rounded as the report writes them.
    pub fn iter(&self) -> impl Iterator<Item = [f64; 4]> + 'a {
        self.times
            .iter()
            .zip(self.poses)
            .map(|(&t, p)| [r6(t), r6(p.x), r6(p.y), r6(p.theta)])
    }
}

impl Serialize for Rows<'_> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(self.iter())
    }
}

/// Final error of dead reckoning against the truth.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct PoseError {
    pub position_m: f64,
    pub heading_deg: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct RobotReport<'a> {
    pub name: String,
    pub follow: String,
    pub truth: Rows<'a>,
    pub odometry: Rows<'a>,
    /// SLAM pose per step, same frame and times as `odometry`.
    pub estimate: Rows<'a>,
    /// ATE and map figures of the SLAM and odometry-only mappers.
    pub slam: super::maps::SlamFigures,
    pub bumps: u32,
    /// Camera frames captured.
    pub frames: usize,
    /// Of those, frames dropped to stay within the frame memory budget.
    pub frames_dropped: usize,
    /// Length of the true path (m).
    pub path_length_m: f64,
    /// Where odometry ended up, against the truth (both in the world frame).
    pub odometry_final_error: PoseError,
}

/// Wall-clock timings measured by the caller (ms).
#[derive(Clone, Debug, Serialize, Default, serde::Deserialize)]
#[serde(default)]
pub struct Timings {
    /// The whole simulation (`slam` is part of it).
    pub simulate: f64,
    /// Capturing camera frames (inside `simulate`) and rendering the ones
    /// looked at: a frame is stored as pose and noise seed and rendered
    /// when first needed, mostly by the merge (inside `features`).
    pub camera: f64,
    /// Both mappers, inside `simulate`; with mappings handed to other
    /// threads (the command line's `--workers`), also their time there,
    /// which the run overlaps.
    pub slam: f64,
    /// SURF on the frames that take part in the merge: the merge's
    /// features stage, plus the wait after the run for frames that worker
    /// threads were describing meanwhile (the command line's `--workers`).
    pub features: f64,
    /// Proposals and frame-pair verification (the matched-pair table).
    pub matching: f64,
    /// Decision and map fusion.
    pub merge: f64,
    pub total: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct Report<'a> {
    pub scenario: String,
    pub seed: u64,
    pub duration_s: f64,
    pub steps: usize,
    /// The merge method (`auto`, `thesis`, `map-only`); null before any merge.
    pub method: Option<String>,
    pub robots: Vec<RobotReport<'a>>,
    /// One matched-pair table per pair of robots (empty before a merge).
    pub match_tables: Vec<crate::merge::job::MatchTable>,
    /// The merge verdict, transforms and their errors; null before a merge.
    pub merge: Option<super::merge::MergeReport>,
    pub timings_ms: Timings,
}

/// Odometry's final pose in the world frame compared with the true one.
pub fn odometry_final_error(start: &Pose2, odom: &Pose2, truth: &Pose2) -> PoseError {
    let believed = start.compose(odom);
    PoseError {
        position_m: r6((believed.position() - truth.position()).length()),
        heading_deg: r6(wrap_angle(believed.theta - truth.theta).to_degrees()),
    }
}

impl<'a> Report<'a> {
    pub fn from_sim(sim: &'a Simulation, timings: Timings) -> Report<'a> {
        let robots = sim
            .robots
            .iter()
            .map(|r| {
                let log = &r.log;
                let path_length_m = log.path_length_m();
                let last = log.truth.len() - 1;
                RobotReport {
                    name: r.spec.name.clone(),
                    follow: match r.spec.follow {
                        crate::scenario::FollowSide::Left => "left".into(),
                        crate::scenario::FollowSide::Right => "right".into(),
                    },
                    truth: Rows::new(&log.times_s, &log.truth),
                    odometry: Rows::new(&log.times_s, &log.odometry),
                    estimate: Rows::new(&log.times_s, r.mapping.estimates()),
                    slam: super::maps::figures(sim, r),
                    bumps: r.bumps,
                    frames: r.frames.next_index(),
                    frames_dropped: r.frames.dropped,
                    path_length_m: r6(path_length_m),
                    odometry_final_error: odometry_final_error(
                        &r.spec.start_pose(),
                        &log.odometry[last],
                        &log.truth[last],
                    ),
                }
            })
            .collect();
        Report {
            scenario: sim.scenario.name.clone(),
            seed: sim.scenario.seed,
            duration_s: sim.time_s(),
            steps: sim.steps(),
            method: None,
            robots,
            match_tables: Vec::new(),
            merge: None,
            timings_ms: timings,
        }
    }

    pub fn to_json(&self) -> String {
        serde_json::to_string(self).unwrap_or_else(|e| format!("{{\"error\":\"{e}\"}}"))
    }

    /// The same JSON as [`Report::to_json`], byte for byte, written to `out`
    /// as it is made (an hour's run of sixteen robots makes 75 MB of it,
    /// which need then never be held whole).
    pub fn write_json<W: std::io::Write>(&self, out: W) -> Result<(), String> {
        serde_json::to_writer(out, self).map_err(|e| format!("writing the report: {e}"))
    }
}

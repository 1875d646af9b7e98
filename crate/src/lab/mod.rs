//! # The lab session
//!
//! [`Lab`] is the one object the page and the command line drive (through
//! the thin [`crate::bindings`] layer): it holds the scenario the user is
//! editing, the simulation once it runs, and the image it renders.
//!
//! Nothing the user made is lost on a bad input: a scenario that fails to
//! parse leaves the current one in place; one whose robots are badly placed
//! is kept (so the page can show the problem) but refuses to run until fixed.
//!
//! This folder is the session layer, the only part of the crate that reads
//! the ground truth (to score and to show it) and the only one the bindings
//! call. The algorithms below it never import it:
//!
//! | file | what the session does there |
//! |---|---|
//! | `mod.rs` | the scenario, the run, the top view, the camera, frames and logs |
//! | [`merge`] | merging the run's maps, the merge's views, scoring it against the truth |
//! | [`groups`] | each group of robots the merge joined: its merged map, its errors |
//! | [`frame_spec`] | a stored frame's parts, for another lab to render and describe |
//! | [`frames`] | a stored frame as grey bytes, PNG or thumbnail |
//! | [`memory`] | where the session's bytes are, structure by structure |
//! | [`maps`] | a robot's maps as files and pictures, their figures against the truth |
//! | [`mapping_away`] | a robot's mapping on another thread: both halves of the hand-off |
//! | [`report`] | the JSON report of a run (`web/cli.mjs run --json`) |
//! | [`views`] | the small JSON views the page reads |
//!
//! Beside the simulated lab, the sessions of the real-data views and
//! commands:
//!
//! | file | session |
//! |---|---|
//! | [`saved_maps`] | saved ROS maps merged (`merge-maps`, "Your maps…") |
//! | [`log_replay`] | a recorded log replayed through SLAM (`run-log`, "Your log…") |
//! | [`bag_file`] | a ROS bag read in pieces: its topics, its log, its maps (`bag-info`) |
//! | [`images`] | SURF on images (`features`, `match`, `bench-surf`) |
//!
//! `Lab`'s fields are private to this folder: callers use its methods.

pub use crate::geom::Pose2;
pub use crate::merge::MergeMethod;
pub use crate::render::RenderOptions;
pub use crate::slam::MapperKind;

use crate::camera::capture::CapturedFrame;
use crate::camera::texture::{ImageTexture, TextureBank};
use crate::camera::{render as render_camera, robot_boxes, CameraImage, PinholeCamera};
use crate::render::{render_world_cached, TrailLayer, ViewLayers};
use crate::scenario::{Scenario, ScenarioError, MAX_DURATION_S};
use crate::sensors::laser::beam_bearing;
use crate::sim::{Simulation, LASER_LOG_NO_RETURN};
use crate::world::World;
use report::{Report, Timings};
use serde::Serialize;
use std::fmt::Write;
use tiny_skia::Pixmap;

/// Checks a scenario fully (shape and placement) and returns it with every
/// default filled in, as pretty JSON.
pub fn validate_scenario(json: &str) -> Result<String, ScenarioError> {
    Ok(Scenario::from_json(json)?.to_json_pretty())
}

/// The robot colours the renderer uses, by robot index, as JSON
/// `[[r, g, b], ...]`.
pub fn robot_colours_json() -> String {
    serde_json::to_string(&crate::palette::ROBOT_COLOURS).unwrap_or_else(|_| "[]".into())
}

pub mod bag_file;
pub mod frame_spec;
pub mod frames;
pub mod groups;
pub mod images;
pub mod log_replay;
pub mod mapping_away;
pub mod maps;
pub mod memory;
pub mod merge;
pub mod report;
pub mod saved_maps;
pub mod views;

/// A lab session: a scenario, and its simulation once started.
pub struct Lab {
    scenario: Scenario,
    sim: Option<Simulation>,
    view: RenderOptions,
    pixmap: Option<Pixmap>,
    /// The view's walls, drawn once while they and the view stay put.
    layers: ViewLayers,
    /// Texture cache and loaded pictures while no simulation holds them.
    textures: Option<TextureBank>,
    /// The world of the scenario being edited (for camera previews).
    preview_world: Option<World>,
    /// The map merge of the current run, once asked for (see
    /// [`merge`]); dropped when the run changes.
    merge: Option<crate::merge::job::MergeJob>,
    /// Features of this run's frames described ahead of a merge by other
    /// threads ([`crate::merge::described_ahead`]); dropped when the run changes.
    described: crate::merge::described_ahead::DescribedFrames,
    /// The host's millisecond clock, for stage timings.
    clock: Option<fn() -> f64>,
    /// Bytes of frames all robots may keep, when not the default
    /// ([`crate::camera::capture::FRAME_BUDGET_BYTES`]).
    frame_budget: Option<usize>,
}

/// Live figures for the page's readouts.
#[derive(Serialize)]
pub struct LabState {
    pub time_s: f64,
    pub steps: usize,
    pub total_steps: usize,
    /// A simulation exists (time may still be 0 right after a reset-run).
    pub started: bool,
    pub finished: bool,
    pub robots: Vec<RobotState>,
}

#[derive(Serialize)]
pub struct RobotState {
    pub name: String,
    pub follow: String,
    pub mode: String,
    /// True pose, world frame `[x, y, theta]`.
    pub truth: [f64; 3],
    /// Believed pose, odometry frame.
    pub odometry: [f64; 3],
    pub sonar_m: [f64; 8],
    pub sonar_no_echo: [bool; 8],
    /// Nearest laser return: range (m) and bearing (deg); null if none.
    pub laser_min: Option<[f64; 2]>,
    pub laser_returns: usize,
    pub bumps: u32,
    pub v_mps: f64,
    pub omega_radps: f64,
    pub odometry_error_m: f64,
}

impl Lab {
    /// A session on the scenario `json`. Fails only if it cannot be parsed
    /// (badly placed robots are allowed while editing).
    pub fn new(json: &str) -> Result<Lab, ScenarioError> {
        let scenario = Scenario::parse(json)?;
        let mut view = RenderOptions::default();
        view.fit(&scenario);
        Ok(Lab {
            scenario,
            sim: None,
            view,
            pixmap: None,
            layers: ViewLayers::default(),
            textures: None,
            preview_world: None,
            merge: None,
            described: Default::default(),
            clock: None,
            frame_budget: None,
        })
    }

    /// Gives the session a millisecond clock: runs then time their camera
    /// and mapping stages, and merges their stages.
    pub fn set_clock(&mut self, clock: fn() -> f64) {
        self.clock = Some(clock);
    }

    pub fn scenario(&self) -> &Scenario {
        &self.scenario
    }

    pub fn simulation(&self) -> Option<&Simulation> {
        self.sim.as_ref()
    }

    /// Replaces the scenario (and stops any run). On error the current
    /// scenario stays.
    pub fn set_scenario(&mut self, json: &str) -> Result<(), ScenarioError> {
        let s = Scenario::parse(json)?;
        self.scenario = s;
        self.stop();
        self.preview_world = None;
        Ok(())
    }

    /// Placement problems that keep the scenario from running.
    pub fn problems(&self) -> Vec<ScenarioError> {
        self.scenario.placement_problems()
    }

    pub fn set_seed(&mut self, seed: u64) {
        self.scenario.seed = seed;
        self.stop();
    }

    /// Sets the bytes of frames all robots may keep (the store thins beyond
    /// it, [`crate::camera::capture`]) and stops the run.
    pub fn set_frame_budget(&mut self, bytes: usize) {
        self.frame_budget = Some(bytes);
        self.stop();
    }

    /// Drops the simulation, keeping its texture bank for the next run.
    fn stop(&mut self) {
        self.merge = None;
        self.layers.trails = TrailLayer::default();
        self.described = Default::default();
        if let Some(sim) = self.sim.take() {
            self.textures = Some(sim.textures.into_inner());
        }
    }

    /// The texture bank for the current scenario: the kept one if it was
    /// made for the same seed and wall height (its pictures always carry over).
    fn take_textures(&mut self) -> TextureBank {
        let (seed, h) = (self.scenario.seed, self.scenario.camera.wall_height_m);
        match self.textures.take() {
            Some(bank) if bank.seed() == seed && bank.wall_height_m() == h => bank,
            Some(old) => old.renewed(seed, h),
            None => TextureBank::new(seed, h),
        }
    }

    pub fn set_duration(&mut self, duration_s: f64) -> Result<(), ScenarioError> {
        if !(duration_s.is_finite() && (0.1..=MAX_DURATION_S).contains(&duration_s)) {
            return Err(ScenarioError {
                field: "duration_s".into(),
                message: format!("{duration_s} is outside [0.1, {MAX_DURATION_S}]"),
            });
        }
        self.scenario.duration_s = duration_s;
        if let Some(sim) = &mut self.sim {
            sim.scenario.duration_s = duration_s;
        }
        Ok(())
    }

    /// Back to time 0 (the editing view).
    pub fn reset(&mut self) {
        self.stop();
    }

    /// Starts the simulation if it is not running.
    pub fn start(&mut self) -> Result<&mut Simulation, ScenarioError> {
        let sim = match self.sim.take() {
            Some(s) => s,
            None => {
                let bank = self.take_textures();
                match Simulation::with_textures(&self.scenario, bank) {
                    Ok(mut s) => {
                        if let Some(clock) = self.clock {
                            s.set_clock(clock);
                        }
                        if let Some(bytes) = self.frame_budget {
                            s.set_frame_budget(bytes);
                        }
                        s
                    }
                    Err(e) => {
                        self.textures = Some(TextureBank::new(
                            self.scenario.seed,
                            self.scenario.camera.wall_height_m,
                        ));
                        return Err(e);
                    }
                }
            }
        };
        Ok(self.sim.insert(sim))
    }

    /// Advances up to `n` steps (fewer at the end of the run); returns how
    /// many were taken.
    pub fn step(&mut self, n: usize) -> Result<usize, ScenarioError> {
        let sim = self.start()?;
        let before = sim.steps();
        if n > 0 && !sim.finished() {
            // The robots move on: a merge of the old maps no longer holds.
            self.merge = None;
        }
        let sim = self.start()?;
        for _ in 0..n {
            if sim.finished() {
                break;
            }
            sim.step();
        }
        let taken = sim.steps() - before;
        self.forget_thinned();
        Ok(taken)
    }

    /// Runs to the end of the scenario's duration.
    pub fn run_to_end(&mut self) -> Result<(), ScenarioError> {
        if !self.start()?.finished() {
            self.merge = None;
        }
        self.start()?.run_to_end();
        self.forget_thinned();
        Ok(())
    }

    /// Drops what other threads described of frames the store has thinned
    /// since: no merge will ask for them.
    fn forget_thinned(&mut self) {
        if let Some(sim) = &self.sim {
            self.described.retain(|robot, index| {
                sim.robots.get(robot).is_some_and(|r| r.frames.holds(index))
            });
        }
    }

    pub fn state(&self) -> LabState {
        let robots = match &self.sim {
            Some(sim) => sim
                .robots
                .iter()
                .map(|r| {
                    let o = r.odometry.pose();
                    let scan = &r.last_scan;
                    let mut laser_min: Option<[f64; 2]> = None;
                    let mut returns = 0;
                    for (i, &rg) in scan.ranges_m.iter().enumerate() {
                        if scan.max_range[i] {
                            continue;
                        }
                        returns += 1;
                        if laser_min.is_none_or(|m| rg < m[0]) {
                            laser_min = Some([rg, beam_bearing(i).to_degrees()]);
                        }
                    }
                    let believed = r.spec.start_pose().compose(&o);
                    RobotState {
                        name: r.spec.name.clone(),
                        follow: format!("{:?}", r.spec.follow).to_lowercase(),
                        mode: r.mode().name().into(),
                        truth: [r.truth.x, r.truth.y, r.truth.theta],
                        odometry: [o.x, o.y, o.theta],
                        sonar_m: r.last_sonar.ranges_m,
                        sonar_no_echo: r.last_sonar.no_echo,
                        laser_min,
                        laser_returns: returns,
                        bumps: r.bumps,
                        v_mps: r.last_command.v_mps,
                        omega_radps: r.last_command.omega_radps,
                        odometry_error_m: (believed.position() - r.truth.position()).length(),
                    }
                })
                .collect(),
            None => Vec::new(),
        };
        let (steps, total) = match &self.sim {
            Some(s) => (s.steps(), s.total_steps()),
            None => (
                0,
                (self.scenario.duration_s / crate::kinematics::CONTROL_DT_S).round() as usize,
            ),
        };
        LabState {
            time_s: steps as f64 * crate::kinematics::CONTROL_DT_S,
            steps,
            total_steps: total,
            started: self.sim.is_some(),
            finished: steps >= total,
            robots,
        }
    }

    pub fn view(&self) -> &RenderOptions {
        &self.view
    }

    /// Sets the view (size, centre, zoom, layers, overlays).
    pub fn set_view(&mut self, view: RenderOptions) -> Result<(), String> {
        view.validate()?;
        self.view = view;
        Ok(())
    }

    /// Fits the view to the scenario at the given canvas size.
    pub fn fit_view(&mut self, width: u32, height: u32) -> Result<&RenderOptions, String> {
        let mut v = self.view.clone();
        v.width = width;
        v.height = height;
        v.validate()?;
        v.fit(&self.scenario);
        self.view = v;
        Ok(&self.view)
    }

    /// Renders the current view; returns the pixmap (straight RGBA, opaque).
    pub fn render(&mut self) -> Result<&Pixmap, String> {
        let (w, h) = (self.view.width, self.view.height);
        let reuse = matches!(&self.pixmap, Some(p) if p.width() == w && p.height() == h);
        if !reuse {
            self.pixmap =
                Some(Pixmap::new(w, h).ok_or_else(|| format!("cannot make a {w}x{h} image"))?);
        }
        let pm = self.pixmap.as_mut().ok_or("no image")?;
        render_world_cached(
            pm,
            &self.scenario,
            self.sim.as_ref(),
            &self.view,
            &mut self.layers,
        );
        Ok(pm)
    }

    /// The run report; the simulation must have been started.
    pub fn report(&self, timings: Timings) -> Result<Report<'_>, String> {
        let sim = self
            .sim
            .as_ref()
            .ok_or("nothing has run yet: run the scenario first")?;
        let mut timings = timings;
        if timings.camera == 0.0 {
            // The caller's `slam` is mapping done on other threads, if any.
            timings.camera = sim.stage_times.camera_ms + sim.render_ms();
            timings.slam += sim.stage_times.slam_ms;
        }
        if let Some(t) = self.merge.as_ref().map(|j| j.times_ms) {
            if timings.matching == 0.0 && timings.merge == 0.0 {
                // The caller's `features` is its wait for frames other
                // threads described (`crate::merge::described_ahead`), if any.
                timings.features += t.features;
                timings.matching = t.matching;
                timings.merge = t.merge;
            }
        }
        let mut report = Report::from_sim(sim, timings);
        if let Some(job) = &self.merge {
            report.method = Some(job.config.method.name().to_string());
            report.match_tables = job.tables();
            report.merge = self.merge_report();
        }
        Ok(report)
    }

    /// Puts a picture (PNG or JPEG bytes) on walls whose texture is
    /// `image:NAME`. Refused with a message if it is not a usable image.
    pub fn add_image_texture(&mut self, name: &str, bytes: &[u8]) -> Result<(), String> {
        if name.is_empty() || name.len() > 64 {
            return Err("a picture's name must have 1 to 64 characters".into());
        }
        let img = ImageTexture::decode(bytes)?;
        match &mut self.sim {
            Some(sim) => sim.textures.get_mut().add_image(name, img.clone()),
            None => {
                let mut bank = self.take_textures();
                bank.add_image(name, img.clone());
                self.textures = Some(bank);
            }
        }
        // Keep it for later runs too.
        if let Some(bank) = &mut self.textures {
            bank.add_image(name, img);
        }
        Ok(())
    }

    /// What robot `i`'s camera sees now (its start pose before a run),
    /// without noise, in colour if asked.
    pub fn camera_view(&mut self, i: usize, colour: bool) -> Result<CameraImage, String> {
        if i >= self.scenario.robots.len() {
            return Err(format!("no robot with index {i}"));
        }
        if let Some(sim) = &mut self.sim {
            return sim
                .camera_view(i, colour)
                .ok_or_else(|| format!("no robot with index {i}"));
        }
        let world = self.preview_world.get_or_insert_with(|| {
            World::new(self.scenario.walls.iter().map(|w| w.segment()).collect())
        });
        let starts: Vec<crate::geom::Pose2> = self
            .scenario
            .robots
            .iter()
            .map(|r| r.start_pose())
            .collect();
        let robots = robot_boxes(&starts, i);
        let mut bank = self.textures.take().unwrap_or_else(|| {
            TextureBank::new(self.scenario.seed, self.scenario.camera.wall_height_m)
        });
        if bank.seed() != self.scenario.seed
            || bank.wall_height_m() != self.scenario.camera.wall_height_m
        {
            bank = bank.renewed(self.scenario.seed, self.scenario.camera.wall_height_m);
        }
        let img = render_camera(
            &PinholeCamera::new(&self.scenario.camera),
            &self.scenario.robots[i].start_pose(),
            world,
            &self.scenario.walls,
            &robots,
            &mut bank,
            colour,
            None,
        );
        self.textures = Some(bank);
        Ok(img)
    }

    /// Robot `i`'s captured frames (empty before a run).
    pub fn frames(&self, i: usize) -> Result<&[CapturedFrame], String> {
        if i >= self.scenario.robots.len() {
            return Err(format!("no robot with index {i}"));
        }
        Ok(match &self.sim {
            Some(sim) => &sim.robots[i].frames.frames,
            None => &[],
        })
    }

    /// The picture a captured frame shows (rendered on demand, see
    /// [`crate::camera::capture`]).
    pub fn frame_image(&self, f: &CapturedFrame) -> Result<crate::camera::CameraImage, String> {
        let sim = self.sim.as_ref().ok_or("nothing has run yet")?;
        Ok(sim.frame_image(f))
    }

    /// Robot `i`'s frame with capture index `index`.
    pub fn frame(&self, i: usize, index: usize) -> Result<&CapturedFrame, String> {
        let frames = self.frames(i)?;
        frames
            .binary_search_by_key(&index, |f| f.index)
            .map(|k| &frames[k])
            .map_err(|_| format!("robot {i} has no frame {index}"))
    }

    /// One robot's log as CSV, in the thesis's layout (§6.2.1): time,
    /// odometry pose, 8 sonars, 181 laser ranges; then the true pose.
    /// Max-range laser beams are written as empty cells.
    pub fn log_csv(&self, robot: usize) -> Result<String, String> {
        let sim = self.sim.as_ref().ok_or("nothing has run yet")?;
        let r = sim
            .robots
            .get(robot)
            .ok_or_else(|| format!("no robot with index {robot}"))?;
        let mut out = String::from("t_s,odom_x_m,odom_y_m,odom_theta_rad");
        for i in 1..=8 {
            let _ = write!(out, ",sonar{i}_m");
        }
        for i in 0..181 {
            let _ = write!(out, ",laser{i}_m");
        }
        out.push_str(",true_x_m,true_y_m,true_theta_rad\n");
        for row in &r.log.sensors {
            let k = row.step;
            let (t, o, g) = (r.log.times_s[k], r.log.odometry[k], r.log.truth[k]);
            let _ = write!(out, "{t:.1},{:.4},{:.4},{:.5}", o.x, o.y, o.theta);
            for s in row.sonar_m {
                let _ = write!(out, ",{s:.3}");
            }
            for l in row.laser_mm {
                if l == LASER_LOG_NO_RETURN {
                    out.push(',');
                } else {
                    let _ = write!(out, ",{:.3}", l as f64 / 1000.0);
                }
            }
            let _ = writeln!(out, ",{:.4},{:.4},{:.5}", g.x, g.y, g.theta);
        }
        Ok(out)
    }
}

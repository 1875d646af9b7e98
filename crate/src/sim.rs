//! # The simulation: a fixed-step loop over sense, decide, move
//!
//! The thesis ran its robots in USARSim and read their sensors from MATLAB
//! (§3.2, §6.1.3); here the whole loop is one deterministic function of the
//! scenario and its seed. Every control step of [`CONTROL_DT_S`]:
//!
//! 1. **decide** — each robot's [`WallFollower`] turns the latest odometry
//!    pose, sonar and laser into a wheel-speed command. It never sees the
//!    truth.
//! 2. **move** — the wheels follow the command within their limits; the true
//!    pose moves on the exact arc. If the body would touch a wall or another
//!    robot, it moves only as far as it can (to within a millimetre of the
//!    contact), its wheels stall, and a *bump* is counted once per contact;
//!    the encoders read only the travel that happened.
//! 3. **odometry** — the encoders read the wheel travels with noise and the
//!    robot integrates its believed pose.
//! 4. **sense** — sonar and laser are cast from the true pose against the
//!    walls and the other robots' bodies.
//! 5. **log** — one row per robot, as the thesis recorded them (§6.2.1):
//!    time, odometry pose, 8 sonar ranges, 181 laser ranges; the true pose is
//!    kept beside it, for scoring only.
//! 6. **map** — each robot's two mappers ([`crate::slam::RobotMapping`])
//!    take the odometry pose and the laser scan (never the truth): SLAM
//!    matches the scan to its map and integrates it at the matched pose; the
//!    odometry-only map, the thesis's baseline, at the odometry pose. After
//!    a robot's first ten minutes both skip the scans their motion filter
//!    drops (under 0.2 m, 5° and 2 s since the last one used;
//!    [`crate::slam::mapper::MotionFilter`]).
//!    The laser is still cast every step: the follower steers by it and
//!    the log and the page show it. Off with [`Simulation::set_mapping`].
//! 7. **capture** — once per camera period, each robot stores a camera frame
//!    ([`crate::camera::capture`]): the instant's odometry and true poses,
//!    sensor row, the other robots' bodies and a noise seed, from which the
//!    picture is rendered on demand ([`Simulation::frame_image`]). Off with
//!    [`Simulation::set_capture`].
//!
//! Row 0 is the start (time 0); a run of `n` steps has `n + 1` rows.

use crate::camera::capture::{CapturedFrame, FrameStore};
use crate::camera::texture::TextureBank;
use crate::camera::{
    render as render_camera, robot_boxes, CameraImage, CameraNoise, PinholeCamera, RobotBox,
};
use crate::follower::{Command, FollowerMode, WallFollower};
use crate::geom::{ConvexPolygon, Pose2, Segment};
use crate::kinematics::{integrate_wheels, wheel_speeds, P2dx, WheelState, CONTROL_DT_S};
use crate::odometry::Odometry;
use crate::rng::{Rng, Stream};
use crate::scenario::{RobotSpec, Scenario, ScenarioError};
use crate::sensors::sonar::SONAR_POSITIONS_M;
use crate::sensors::{Laser, LaserScan, RangeScene, Sonar, SonarReading, LASER_BEAMS, SONAR_COUNT};
use crate::slam::handoff::{mapping_from_bytes, mapping_to_bytes, pack_step};
use crate::world::World;
use std::collections::VecDeque;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, MutexGuard};

/// The log keeps at most this many sensor rows per robot (20 simulated
/// minutes at 10 Hz, about 4.5 MB). Older sensor rows are dropped first;
/// poses (a few bytes a row) are always kept whole.
pub const LOG_SENSOR_CAP: usize = 12_000;

/// Laser ranges are logged in millimetres; this value marks a max-range
/// (no return) beam.
pub const LASER_LOG_NO_RETURN: u16 = u16::MAX;

/// One robot's sensor row as logged.
#[derive(Clone, Debug, PartialEq)]
pub struct SensorRow {
    pub step: usize,
    /// Sonar ranges 1..8 (m).
    pub sonar_m: [f32; SONAR_COUNT],
    /// Laser ranges (mm), [`LASER_LOG_NO_RETURN`] for no return.
    pub laser_mm: [u16; LASER_BEAMS],
}

/// Everything recorded about one robot, one row per control step.
#[derive(Clone, Debug, Default)]
pub struct RobotLog {
    pub times_s: Vec<f64>,
    /// What the robot believes (its odometry frame).
    pub odometry: Vec<Pose2>,
    /// Where it really was (world frame). For scoring and display only.
    pub truth: Vec<Pose2>,
    /// The most recent sensor rows, at most [`LOG_SENSOR_CAP`].
    pub sensors: VecDeque<SensorRow>,
    /// Sensor rows dropped because of the cap.
    pub sensors_dropped: usize,
}

impl RobotLog {
    /// An empty log with room for the rows of a run of `steps` steps
    /// (one more than the steps: row 0 is the start), reserved once
    /// rather than doubled into (a doubled row list holds up to twice its
    /// rows, and copies itself at each doubling).
    pub fn for_steps(steps: usize) -> RobotLog {
        RobotLog {
            times_s: Vec::with_capacity(steps + 1),
            odometry: Vec::with_capacity(steps + 1),
            truth: Vec::with_capacity(steps + 1),
            ..RobotLog::default()
        }
    }

    /// Length of the true path so far (m).
    pub fn path_length_m(&self) -> f64 {
        self.truth
            .windows(2)
            .map(|w| (w[1].position() - w[0].position()).length())
            .sum()
    }
}

/// One simulated robot: its true state, its noisy senses, and its controller.
#[derive(Clone, Debug)]
pub struct RobotSim {
    pub spec: RobotSpec,
    /// True pose in the world frame (never shown to the controller).
    pub truth: Pose2,
    wheels: WheelState,
    pub odometry: Odometry,
    sonar: Sonar,
    laser: Laser,
    pub follower: WallFollower,
    pub bumps: u32,
    in_contact: bool,
    bumped_last_step: bool,
    pub last_sonar: SonarReading,
    pub last_scan: LaserScan,
    pub last_command: Command,
    pub log: RobotLog,
    /// The robot's two mappers (odometry-only and SLAM), fed each step.
    pub mapping: crate::slam::RobotMapping,
    /// While the mapping is away on another thread
    /// ([`Simulation::send_mapping_away`]): the steps it has yet to be
    /// sent, packed ([`crate::slam::handoff::pack_step`]).
    slam_outbox: Option<Vec<u8>>,
    /// While the mapping is away: its estimates as the other thread last
    /// reported them ([`Simulation::note_away_estimates`]; closures found
    /// since may have moved them), for guesses made during the run.
    away_estimates: Vec<Pose2>,
    /// Frames captured by the camera.
    pub frames: FrameStore,
    camera_rng: Rng,
}

impl RobotSim {
    /// SLAM poses so far, one per step from the start: the mapping's, or
    /// while it is away, what the other thread last reported (fewer rows
    /// than steps when it lags).
    pub fn slam_estimates(&self) -> &[Pose2] {
        match self.slam_outbox {
            Some(_) => &self.away_estimates,
            None => self.mapping.estimates(),
        }
    }

    pub fn body(&self) -> ConvexPolygon {
        P2dx::body(&self.truth)
    }

    /// Full opening of each sonar cone (rad).
    pub fn sonar_cone_rad(&self) -> f64 {
        self.sonar.cone_rad
    }

    pub fn mode(&self) -> FollowerMode {
        self.follower.mode()
    }

    fn log_row(&mut self, step: usize, t: f64) {
        self.log.times_s.push(t);
        self.log.odometry.push(self.odometry.pose());
        self.log.truth.push(self.truth);
        let mut sonar_m = [0f32; SONAR_COUNT];
        for (o, r) in sonar_m.iter_mut().zip(self.last_sonar.ranges_m) {
            *o = r as f32;
        }
        let mut laser_mm = [0u16; LASER_BEAMS];
        for (i, o) in laser_mm.iter_mut().enumerate() {
            *o = if self.last_scan.max_range[i] {
                LASER_LOG_NO_RETURN
            } else {
                (self.last_scan.ranges_m[i] * 1000.0).round().min(65_000.0) as u16
            };
        }
        if self.log.sensors.len() == LOG_SENSOR_CAP {
            self.log.sensors.pop_front();
            self.log.sensors_dropped += 1;
        } else if self.log.sensors.len() == self.log.sensors.capacity() {
            // Doubling, but never past the cap: a deque left to double
            // would reserve 16,384 rows (6.4 MB) for 12,000.
            let len = self.log.sensors.len();
            self.log
                .sensors
                .reserve_exact(len.max(64).min(LOG_SENSOR_CAP - len));
        }
        self.log.sensors.push_back(SensorRow {
            step,
            sonar_m,
            laser_mm,
        });
    }
}

/// The whole multi-robot simulation.
#[derive(Clone, Debug)]
pub struct Simulation {
    pub scenario: Scenario,
    pub world: World,
    pub robots: Vec<RobotSim>,
    steps: usize,
    pub camera: PinholeCamera,
    /// Wall textures, generated on first use (hence a cell: rendering a
    /// stored frame reads the simulation, it does not change it).
    pub textures: TextureCache,
    /// Whether frames are captured (off only for experiments that need no
    /// images, e.g. controller tests; it changes nothing else in the run).
    capture: bool,
    /// Whether the robots' mappers run (off only for experiments that need
    /// no maps; mapping reads the senses and changes nothing else).
    mapping: bool,
    /// A millisecond clock, if the host provides one (the core has no clock
    /// of its own: wasm32-unknown-unknown has none); see [`StageTimes`].
    clock: Option<fn() -> f64>,
    /// Time spent in the camera and in the mappers so far.
    pub stage_times: StageTimes,
    /// Time spent rendering stored frames ([`Simulation::frame_image`]), ms.
    render_ms: Millis,
}

/// The texture bank, which rendering a stored frame fills in as it reads
/// the simulation: behind a lock, so that a `&Simulation` can render (and
/// be shared, as tests do) while the textures are generated on first use.
#[derive(Debug)]
pub struct TextureCache(Mutex<TextureBank>);

impl TextureCache {
    /// The bank, for one rendering. A panic while rendering cannot leave
    /// the bank half-written in a way that matters (a texture is inserted
    /// whole), so a poisoned lock is simply taken over.
    pub fn lock(&self) -> MutexGuard<'_, TextureBank> {
        self.0.lock().unwrap_or_else(|e| e.into_inner())
    }

    pub fn get_mut(&mut self) -> &mut TextureBank {
        self.0.get_mut().unwrap_or_else(|e| e.into_inner())
    }

    pub fn into_inner(self) -> TextureBank {
        self.0.into_inner().unwrap_or_else(|e| e.into_inner())
    }
}

impl Clone for TextureCache {
    fn clone(&self) -> Self {
        TextureCache(Mutex::new(self.lock().clone()))
    }
}

/// A millisecond total that a `&Simulation` can add to.
#[derive(Debug, Default)]
struct Millis(AtomicU64);

impl Millis {
    fn get(&self) -> f64 {
        f64::from_bits(self.0.load(Ordering::Relaxed))
    }

    fn add(&self, ms: f64) {
        self.0.store((self.get() + ms).to_bits(), Ordering::Relaxed);
    }
}

impl Clone for Millis {
    fn clone(&self) -> Self {
        Millis(AtomicU64::new(self.0.load(Ordering::Relaxed)))
    }
}

/// Milliseconds spent in the expensive stages of [`Simulation::step`],
/// measured with the clock given to [`Simulation::set_clock`] (zero
/// without one). Reading a clock changes nothing in the run.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StageTimes {
    /// Capturing frames (pose, senses, noise seed); rendering them is timed
    /// apart, when it happens ([`Simulation::render_ms`]).
    pub camera_ms: f64,
    pub slam_ms: f64,
}

impl Simulation {
    /// Builds a simulation at time 0. Fails, naming the field, if a robot
    /// starts inside or touching a wall or another robot.
    pub fn new(scenario: &Scenario) -> Result<Simulation, ScenarioError> {
        Self::with_textures(
            scenario,
            TextureBank::new(scenario.seed, scenario.camera.wall_height_m),
        )
    }

    /// Like [`Simulation::new`], with a texture bank that may hold pictures
    /// the user loaded.
    pub fn with_textures(
        scenario: &Scenario,
        textures: TextureBank,
    ) -> Result<Simulation, ScenarioError> {
        if let Some(p) = scenario.placement_problems().into_iter().next() {
            return Err(p);
        }
        let camera = PinholeCamera::new(&scenario.camera);
        let frame_bytes = crate::camera::capture::FRAME_BYTES;
        let period_steps = ((scenario.camera.period_s / CONTROL_DT_S).round() as usize).max(1);
        let n_robots = scenario.robots.len();
        let world = World::new(scenario.walls.iter().map(|w| w.segment()).collect());
        let seed = scenario.seed;
        let robots = scenario
            .robots
            .iter()
            .enumerate()
            .map(|(i, spec)| {
                let n = &scenario.noise;
                let s = &scenario.sensors;
                RobotSim {
                    spec: spec.clone(),
                    truth: spec.start_pose(),
                    wheels: WheelState::default(),
                    odometry: Odometry::new(n, Rng::stream(seed, i, Stream::Odometry)),
                    sonar: Sonar::new(
                        s.sonar_range_m,
                        s.sonar_cone_deg,
                        n.sonar_std_m,
                        Rng::stream(seed, i, Stream::Sonar),
                    ),
                    laser: Laser::new(
                        s.laser_range_m,
                        n.laser_std_m,
                        Rng::stream(seed, i, Stream::Laser),
                    ),
                    follower: WallFollower::new(spec.follow, spec.distance, spec.speed),
                    bumps: 0,
                    in_contact: false,
                    bumped_last_step: false,
                    last_sonar: SonarReading::default(),
                    last_scan: LaserScan {
                        ranges_m: vec![0.0; LASER_BEAMS],
                        max_range: vec![true; LASER_BEAMS],
                        reflective: vec![false; LASER_BEAMS],
                        range_max_m: s.laser_range_m,
                    },
                    last_command: Command::default(),
                    log: RobotLog::for_steps(scenario_steps(scenario)),
                    mapping: crate::slam::RobotMapping::default(),
                    slam_outbox: None,
                    away_estimates: Vec::new(),
                    frames: FrameStore::new(frame_bytes, n_robots, period_steps),
                    camera_rng: Rng::stream(seed, i, Stream::Camera),
                }
            })
            .collect();
        let mut sim = Simulation {
            scenario: scenario.clone(),
            world,
            robots,
            steps: 0,
            camera,
            textures: TextureCache(Mutex::new(textures)),
            capture: true,
            mapping: true,
            clock: None,
            stage_times: StageTimes::default(),
            render_ms: Millis::default(),
        };
        sim.sense();
        for r in &mut sim.robots {
            r.log_row(0, 0.0);
        }
        sim.capture_due_frames();
        Ok(sim)
    }

    /// Shares a frame budget of `bytes` among the robots' frame stores
    /// instead of [`crate::camera::capture::FRAME_BUDGET_BYTES`] (for tests
    /// and measurements of thinning; a store over its new share thins at
    /// its next frame).
    pub fn set_frame_budget(&mut self, bytes: usize) {
        let n = self.robots.len();
        for r in &mut self.robots {
            r.frames
                .set_budget(bytes, crate::camera::capture::FRAME_BYTES, n);
        }
    }

    /// Control steps taken so far.
    pub fn steps(&self) -> usize {
        self.steps
    }

    /// Simulated time (s).
    pub fn time_s(&self) -> f64 {
        self.steps as f64 * CONTROL_DT_S
    }

    /// Total steps the scenario's duration asks for.
    pub fn total_steps(&self) -> usize {
        scenario_steps(&self.scenario)
    }

    pub fn finished(&self) -> bool {
        self.steps >= self.total_steps()
    }

    /// Body edges of every robot except `skip` that robot `skip`'s laser or
    /// sonars could reach: a robot whose centre is farther than the longer
    /// sensor range plus both reaches (the body's circumradius, and the
    /// farthest sensor from the centre) cannot be hit, so its edges are left
    /// out. The kept edges keep their order, so every ray's answer, ties
    /// included, is the one casting against all robots gives; with 16
    /// robots in a big maze most are out of reach, and testing their edges
    /// was a fifth of the simulation's time.
    fn obstacles_near(&self, skip: usize) -> Vec<Segment> {
        let me = &self.robots[skip];
        let body_radius = 0.5 * P2dx::BODY_LENGTH_M.hypot(P2dx::BODY_WIDTH_M);
        let sensor_reach = SONAR_POSITIONS_M
            .iter()
            .map(|p| p[0].hypot(p[1]))
            .fold(body_radius, f64::max);
        let reach = me.laser.range_m.max(me.sonar.range_m) + sensor_reach + body_radius;
        let centre = me.truth.position();
        self.robots
            .iter()
            .enumerate()
            .filter(|(j, r)| *j != skip && r.truth.position().distance(centre) <= reach)
            .flat_map(|(_, r)| r.body().edges().collect::<Vec<_>>())
            .collect()
    }

    fn sense(&mut self) {
        for i in 0..self.robots.len() {
            let obstacles = self.obstacles_near(i);
            let scene = RangeScene {
                world: &self.world,
                obstacles: &obstacles,
            };
            let r = &mut self.robots[i];
            r.last_sonar = r.sonar.read(&scene, &r.truth);
            r.last_scan = r.laser.scan(&scene, &r.truth);
        }
    }

    /// Advances one control step. Does nothing once the duration is reached.
    pub fn step(&mut self) {
        self.step_with(&[]);
    }

    /// Advances one control step with some robots driven by hand:
    /// `overrides[i]`, when given and `Some`, replaces robot `i`'s follower
    /// command (teleoperation, and tests of the physics).
    pub fn step_with(&mut self, overrides: &[Option<Command>]) {
        if self.finished() {
            return;
        }
        let t = self.time_s();
        // 1. decide
        for (i, r) in self.robots.iter_mut().enumerate() {
            let odom = r.odometry.pose();
            let auto = r
                .follower
                .update(t, &odom, &r.last_sonar, &r.last_scan, r.bumped_last_step);
            r.last_command = overrides.get(i).copied().flatten().unwrap_or(auto);
        }
        // 2-3. move and read encoders
        // Two bodies can touch only when their centres are within both
        // circumradii plus this step's travel (at most a few centimetres);
        // bodies farther than that (with a generous margin) are left out,
        // which changes no answer.
        let touch_reach = P2dx::BODY_LENGTH_M.hypot(P2dx::BODY_WIDTH_M) + 0.5;
        for i in 0..self.robots.len() {
            let centre = self.robots[i].truth.position();
            let others: Vec<ConvexPolygon> = self
                .robots
                .iter()
                .enumerate()
                .filter(|(j, r)| *j != i && r.truth.position().distance(centre) <= touch_reach)
                .map(|(_, r)| r.body())
                .collect();
            let world = &self.world;
            let r = &mut self.robots[i];
            let (cl, cr) = wheel_speeds(
                r.last_command.v_mps,
                r.last_command.omega_radps,
                P2dx::WHEEL_BASE_M,
            );
            let mut probe = r.wheels;
            let (dl, dr) = probe.advance(cl, cr, CONTROL_DT_S);
            let free = |f: f64| {
                let body = P2dx::body(&integrate_wheels(
                    &r.truth,
                    f * dl,
                    f * dr,
                    P2dx::WHEEL_BASE_M,
                ));
                !(world.body_hits_wall(&body) || others.iter().any(|o| o.touches(&body)))
            };
            if free(1.0) {
                r.in_contact = false;
                r.bumped_last_step = false;
                r.wheels = probe;
                r.truth = integrate_wheels(&r.truth, dl, dr, P2dx::WHEEL_BASE_M);
                r.odometry.update(dl, dr);
            } else {
                // Blocked: move as far as the body can go (to within 1 mm of
                // the contact), then stall. One bump per contact.
                let (mut lo, mut hi) = (0.0, 1.0);
                while (hi - lo) * dl.abs().max(dr.abs()) > 0.001 {
                    let mid = 0.5 * (lo + hi);
                    if free(mid) {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                if !r.in_contact {
                    r.bumps += 1;
                }
                r.in_contact = true;
                r.bumped_last_step = true;
                r.wheels.stop();
                r.truth = integrate_wheels(&r.truth, lo * dl, lo * dr, P2dx::WHEEL_BASE_M);
                r.odometry.update(lo * dl, lo * dr);
            }
        }
        self.steps += 1;
        // 4. sense
        self.sense();
        // 5. log
        let (step, t) = (self.steps, self.time_s());
        for r in &mut self.robots {
            r.log_row(step, t);
        }
        // 6. map: odometry pose and scan into both mappers (never the truth)
        let t0 = self.clock.map_or(0.0, |now| now());
        if self.mapping {
            for r in &mut self.robots {
                match &mut r.slam_outbox {
                    Some(out) => pack_step(&r.odometry.pose(), &r.last_scan, out),
                    None => r.mapping.observe(&r.odometry.pose(), &r.last_scan),
                }
            }
            if self.finished() {
                self.settle_maps();
            }
        }
        // 7. capture: camera frames, once per capture period
        let t1 = self.clock.map_or(0.0, |now| now());
        self.capture_due_frames();
        if let Some(now) = self.clock {
            self.stage_times.slam_ms += t1 - t0;
            self.stage_times.camera_ms += now() - t1;
        }
    }

    /// Completes every SLAM map the loop-closing back end is still
    /// redrawing ([`crate::slam::RobotMapping::settle`]): done at the last
    /// step, and before a merge reads the maps of a paused run.
    pub fn settle_maps(&mut self) {
        for r in &mut self.robots {
            r.mapping.settle();
        }
    }

    /// Gives the simulation a millisecond clock to time its stages with
    /// ([`Simulation::stage_times`]).
    pub fn set_clock(&mut self, clock: fn() -> f64) {
        self.clock = Some(clock);
    }

    /// The other robots as boxes for robot `skip`'s camera.
    fn robot_boxes_except(&self, skip: usize) -> Vec<RobotBox> {
        let poses: Vec<Pose2> = self.robots.iter().map(|r| r.truth).collect();
        robot_boxes(&poses, skip)
    }

    /// What robot `i`'s camera sees now, noise-free (for display), in
    /// colour if asked.
    pub fn camera_view(&mut self, i: usize, colour: bool) -> Option<CameraImage> {
        let boxes = self.robot_boxes_except(i);
        let pose = self.robots.get(i)?.truth;
        Some(render_camera(
            &self.camera,
            &pose,
            &self.world,
            &self.scenario.walls,
            &boxes,
            &mut self.textures.lock(),
            colour,
            None,
        ))
    }

    /// Turns frame capture off or on. Capture draws no random numbers the
    /// robots use, so the run is otherwise the same.
    pub fn set_capture(&mut self, on: bool) {
        self.capture = on;
    }

    /// Turns the robots' mappers off or on (see [`Simulation::set_capture`]).
    pub fn set_mapping(&mut self, on: bool) {
        self.mapping = on;
    }

    /// Hands robot `i`'s mapping to another thread: returns it as bytes
    /// ([`crate::slam::handoff`]); from now on its steps wait, packed, for
    /// [`Simulation::take_mapping_steps`] instead of being observed here,
    /// and the robot's mapping here is an empty one until
    /// [`Simulation::bring_mapping_home`]. Nothing of the run reads it
    /// meanwhile but the SLAM poses of the frames picked to describe, which
    /// come from what the other thread reports
    /// ([`Simulation::note_away_estimates`], [`RobotSim::slam_estimates`]).
    pub fn send_mapping_away(&mut self, i: usize) -> Result<Vec<u8>, String> {
        let r = self.robot_mut(i)?;
        if r.slam_outbox.is_some() {
            return Err(format!("robot {i}'s mapping is away already"));
        }
        let bytes = mapping_to_bytes(&r.mapping)?;
        r.away_estimates = r.mapping.estimates().to_vec();
        r.mapping = crate::slam::RobotMapping::new(r.mapping.config.clone());
        r.slam_outbox = Some(Vec::new());
        Ok(bytes)
    }

    fn robot_mut(&mut self, i: usize) -> Result<&mut RobotSim, String> {
        self.robots
            .get_mut(i)
            .ok_or_else(|| format!("no robot {i}"))
    }

    /// The steps robot `i`'s mapping, away, has not been sent yet (packed,
    /// oldest first; empty when its mapping is at home).
    pub fn take_mapping_steps(&mut self, i: usize) -> Vec<u8> {
        self.robots
            .get_mut(i)
            .and_then(|r| r.slam_outbox.as_mut())
            .map(std::mem::take)
            .unwrap_or_default()
    }

    /// Appends the estimates robot `i`'s mapping, away, reports for its
    /// newest steps (`[x, y, θ]` a step, in order).
    pub fn note_away_estimates(&mut self, i: usize, flat: &[f64]) -> Result<(), String> {
        let steps = self.steps;
        let r = self.robot_mut(i)?;
        if r.slam_outbox.is_none() {
            return Err(format!("robot {i}'s mapping is not away"));
        }
        if !flat.len().is_multiple_of(3) || r.away_estimates.len() + flat.len() / 3 > steps + 1 {
            return Err(format!(
                "robot {i}: {} numbers are not the estimates of steps it made",
                flat.len()
            ));
        }
        let poses = flat.chunks_exact(3).map(|p| Pose2::new(p[0], p[1], p[2]));
        r.away_estimates.extend(poses);
        Ok(())
    }

    /// Takes robot `i`'s mapping back (the bytes of the mapping it was sent
    /// away as, fed every step since): it must have seen every step of the
    /// run so far, one estimate per step.
    pub fn bring_mapping_home(&mut self, i: usize, bytes: &[u8]) -> Result<(), String> {
        let (steps, mapping_on) = (self.steps, self.mapping);
        let settle = self.finished() && mapping_on;
        let r = self.robot_mut(i)?;
        let outbox = r
            .slam_outbox
            .as_ref()
            .ok_or_else(|| format!("robot {i}'s mapping is not away"))?;
        if !outbox.is_empty() {
            return Err(format!("robot {i}'s mapping has steps it was not sent"));
        }
        let mapping = mapping_from_bytes(bytes)?;
        let seen = mapping.estimates().len().saturating_sub(1);
        if mapping_on && seen != steps {
            return Err(format!(
                "robot {i}'s mapping came back having seen {seen} steps of {steps}"
            ));
        }
        r.mapping = mapping;
        r.slam_outbox = None;
        r.away_estimates = Vec::new();
        if settle {
            // As the last step does at home (idempotent).
            r.mapping.settle();
        }
        Ok(())
    }

    fn capture_due_frames(&mut self) {
        if !self.capture {
            return;
        }
        let step = self.steps;
        for i in 0..self.robots.len() {
            if !self.robots[i].frames.due(step) {
                continue;
            }
            let others = self.robot_boxes_except(i);
            let r = &mut self.robots[i];
            let row = r.log.sensors.back().cloned();
            let frame = CapturedFrame {
                index: 0,
                step,
                time_s: step as f64 * CONTROL_DT_S,
                odometry: r.odometry.pose(),
                truth: r.truth,
                sonar_m: row.as_ref().map_or([0.0; SONAR_COUNT], |s| s.sonar_m),
                laser_mm: row
                    .as_ref()
                    .map_or([LASER_LOG_NO_RETURN; LASER_BEAMS], |s| s.laser_mm),
                width: self.camera.width,
                height: self.camera.height,
                others,
                noise_seed: r.camera_rng.next_u64(),
            };
            r.frames.push(frame);
        }
    }

    /// The picture stored frame `f` shows: rendered now from the static
    /// world, the pose and other robots of its instant and its own noise
    /// seed, so it is the same whenever (and however often) it is asked
    /// for. About 2 ms at 320 × 240.
    pub fn frame_image(&self, f: &CapturedFrame) -> CameraImage {
        self.render_stored(&f.truth, &f.others, f.noise_seed)
    }

    /// What a stored frame with this pose, these other robots' bodies and
    /// this noise seed shows ([`Simulation::frame_image`] of its parts): a
    /// second simulation of the same scenario renders the same picture, which
    /// is what lets another thread describe the frames of this one
    /// ([`crate::merge::described_ahead`]).
    pub fn render_stored(
        &self,
        truth: &Pose2,
        others: &[RobotBox],
        noise_seed: u64,
    ) -> CameraImage {
        let spec = &self.scenario.camera;
        let mut rng = Rng::new(noise_seed);
        let t0 = self.clock.map_or(0.0, |now| now());
        let img = render_camera(
            &self.camera,
            truth,
            &self.world,
            &self.scenario.walls,
            others,
            &mut self.textures.lock(),
            false,
            Some(CameraNoise {
                rng: &mut rng,
                pixel_std: spec.pixel_noise_std,
                exposure_std: spec.exposure_jitter,
            }),
        );
        if let Some(now) = self.clock {
            self.render_ms.add(now() - t0);
        }
        img
    }

    /// Milliseconds spent rendering stored frames so far (zero without a
    /// clock, see [`Simulation::set_clock`]).
    pub fn render_ms(&self) -> f64 {
        self.render_ms.get()
    }

    /// Runs to the end of the scenario's duration.
    pub fn run_to_end(&mut self) {
        while !self.finished() {
            self.step();
        }
    }
}

/// Control steps in a run of `scenario`'s duration.
fn scenario_steps(scenario: &Scenario) -> usize {
    (scenario.duration_s / CONTROL_DT_S).round() as usize
}

//! # Wall following (thesis §6.2.1)
//!
//! In the thesis each robot "always keeps a fixed distance from the wall on
//! its left or right side": the controller reads the side sonar (sonar 1 on
//! the left, sonar 8 on the right) and corrects the wheel speeds when the
//! range drifts from 0.6 m. That rule alone holds a straight wall; to tour a
//! whole maze a follower must also turn at inside corners, round outside
//! corners and wall ends, escape dead ends, and find a wall when it starts in
//! open space. We do all of these with one geometric rule:
//!
//! > **Follow the nearest point on the chosen side.** Let `p` be the nearest
//! > obstacle point on the follow side (or straight ahead), at distance `r`
//! > in direction `n`. The wall runs perpendicular to `n`, so the tangent
//! > `t = n` turned by −90° (left wall) or +90° (right wall) is the direction
//! > that keeps the wall on that side. Steer along `t + k·(r − r*)·n`: along
//! > the wall, leaning in when too far and out when too close.
//!
//! * straight wall: `n` points sideways, `t` straight ahead;
//! * inside corner: the wall ahead becomes the nearest point, `n` points
//!   forward, `t` sideways, so the robot turns in place away from the wall;
//! * outside corner or wall end: the end point stays nearest while the robot
//!   passes it, `n` swings backwards and the robot arcs around the end at
//!   radius `r*`;
//! * open space: no point within reach, so drive straight until one appears.
//!
//! The laser sees only the front half-plane, so points are kept in a short
//! *local memory* in the odometry frame: each step the current scan replaces
//! everything in the laser's field of view, and remembered points survive
//! only behind it (where a wall end being rounded lies) and within 2.5 m.
//!
//! Other robots are not walls. Their laser returns are bright (reflective
//! tape, see [`crate::sensors::laser`]), so they are left out of the wall
//! points. Two followers touring the same wall in opposite directions (the
//! thesis's setup: one keeps the wall on its left, one on its right) meet
//! head-on in the same lane. They pass by a keep-right rule that needs no
//! communication: a left-wall follower, whose right side is free, goes
//! around the oncoming robot keeping it on its left as if it were a wall
//! end; a right-wall follower, whose right side is the wall, holds still and
//! lets it pass (and, if still blocked after [`MAX_WAIT_S`], goes around it
//! on its own free side). Two left-followers meeting head-on both swerve to
//! their right and so pass each other. A robot ahead moving our way is
//! simply followed at a distance. Going around another robot takes us away
//! from our wall, where the nearest point may now be on something else (a
//! pillar we would then circle for ever); so the wall we were following is
//! remembered as a line when the encounter starts, and for a few seconds
//! after it only points on that line are candidates, until we are back.
//!
//! The distance `r` is measured from the robot's centre. Where the nearest
//! point is abeam, the thesis's own measurement is used instead: the side
//! sonar's range plus the sonar's offset from the centre, so the follower
//! holds `distance` *as the side sonar reads it*. A speed limit from the free
//! space ahead, a push away from anything closer than the body allows, and a
//! short back-off after a bump keep the body off the walls.

use crate::geom::{Pose2, PoseFrame};
use crate::kinematics::P2dx;
use crate::scenario::FollowSide;
use crate::sensors::sonar::{SONAR_BEARINGS_DEG, SONAR_POSITIONS_M};
use crate::sensors::{LaserScan, SonarReading};
use glam::DVec2;

/// Points further than this from the robot are forgotten (m).
const MEMORY_RADIUS_M: f64 = 2.5;
/// The current scan covers bearings within this of straight ahead (rad).
pub const SCAN_COVER_RAD: f64 = 88.0 * std::f64::consts::PI / 180.0;

/// Whether the robot-frame point `q` lies outside the scan's cover:
/// `|atan2(q.y, q.x)| > SCAN_COVER_RAD`. Decided from the tangent (88° is
/// below 90°: beyond it exactly when `|y| > x · tan 88°` or `x < 0`), and
/// by the arctangent itself only within a relative 1e-9 of the boundary,
/// far wider than either's rounding, so the answer is always the
/// arctangent's, at a fraction of its cost.
///
/// `tan_cover` is `SCAN_COVER_RAD.tan()`. (Points closer to the y axis than
/// 1e-200 m, where products lose precision, go to the arctangent.)
pub fn outside_scan_cover(q: DVec2, tan_cover: f64) -> bool {
    if q.x < 0.0 {
        return true;
    }
    if q.x > 1e-200 {
        let edge = q.x * tan_cover;
        let y = q.y.abs();
        if y > edge * (1.0 + 1e-9) {
            return true;
        }
        if y < edge * (1.0 - 1e-9) {
            return false;
        }
    }
    q.y.atan2(q.x).abs() > SCAN_COVER_RAD
}

/// Gain from distance error to lean toward / away from the wall (1/m).
const LEAN_GAIN: f64 = 3.0;
/// Gain from heading error to turn rate (1/s).
const TURN_GAIN: f64 = 2.2;
/// Fastest turn (rad/s).
const MAX_TURN_RATE: f64 = 1.2;
/// Anything closer than this to the centre pushes the robot away (m).
const PERSONAL_SPACE_M: f64 = 0.42;
/// Stop moving forward when the free space ahead of the bumper is this short (m).
const STOP_GAP_M: f64 = 0.12;
/// How long to back off after a bump (s).
const RECOVER_S: f64 = 1.0;
/// A robot within this distance ahead and this far to either side is in our
/// lane (m).
const LANE_AHEAD_M: f64 = 1.6;
const LANE_HALF_WIDTH_M: f64 = 0.6;
/// Distance from our centre to the nearest point of a robot we go around (m).
const PASSING_CLEARANCE_M: f64 = 0.75;
/// A robot holding still for an oncoming one gives up waiting after this (s).
pub const MAX_WAIT_S: f64 = 10.0;
/// After an encounter, look for the remembered wall for this long (s).
const REACQUIRE_S: f64 = 10.0;
/// Points within this of the remembered wall's line belong to it (m).
const WALL_LINE_TOLERANCE_M: f64 = 0.35;

/// A velocity command for the body: forward speed and turn rate.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Command {
    pub v_mps: f64,
    pub omega_radps: f64,
}

/// What the follower is doing, for display and logs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FollowerMode {
    /// No wall within reach: drive straight to find one.
    Seek,
    /// Following the wall on its side.
    Follow,
    /// Turning in place (inside corner, dead end).
    Turn,
    /// Backing off after a bump.
    Recover,
    /// Holding still while an oncoming robot goes around.
    Yield,
    /// Going around an oncoming robot.
    Pass,
}

impl FollowerMode {
    pub fn name(self) -> &'static str {
        match self {
            FollowerMode::Seek => "seek",
            FollowerMode::Follow => "follow",
            FollowerMode::Turn => "turn",
            FollowerMode::Recover => "recover",
            FollowerMode::Yield => "yield",
            FollowerMode::Pass => "pass",
        }
    }
}

/// The wall follower of one robot. It sees only odometry, sonar and laser.
#[derive(Clone, Debug)]
pub struct WallFollower {
    side: FollowSide,
    /// Clearance to hold, as the side sonar reads it (m).
    distance_m: f64,
    /// The same clearance measured from the robot's centre (m).
    centre_distance_m: f64,
    cruise_mps: f64,
    /// Remembered wall points (odometry frame).
    memory: Vec<DVec2>,
    /// Other robots seen in the current scan (odometry frame).
    robots_seen: Vec<DVec2>,
    /// Centroid of the robot returns in the previous scan (odometry frame).
    last_robot_centroid: Option<DVec2>,
    /// Since when we have been holding still for an oncoming robot.
    waiting_since_s: Option<f64>,
    /// The wall followed when an encounter began: a point on it and its
    /// direction (odometry frame), and until when to look for it.
    wall_line: Option<(DVec2, DVec2)>,
    reacquire_until_s: f64,
    mode: FollowerMode,
    recover_until_s: f64,
}

impl WallFollower {
    pub fn new(side: FollowSide, distance_m: f64, cruise_mps: f64) -> Self {
        let side_sonar = Self::side_sonar_index(side);
        WallFollower {
            side,
            distance_m,
            centre_distance_m: distance_m + SONAR_POSITIONS_M[side_sonar][1].abs(),
            cruise_mps,
            memory: Vec::new(),
            robots_seen: Vec::new(),
            last_robot_centroid: None,
            waiting_since_s: None,
            wall_line: None,
            reacquire_until_s: f64::NEG_INFINITY,
            mode: FollowerMode::Seek,
            recover_until_s: f64::NEG_INFINITY,
        }
    }

    /// Sonar 1 (index 0) for a left wall, sonar 8 (index 7) for a right one.
    pub fn side_sonar_index(side: FollowSide) -> usize {
        match side {
            FollowSide::Left => 0,
            FollowSide::Right => 7,
        }
    }

    pub fn mode(&self) -> FollowerMode {
        self.mode
    }

    pub fn distance_m(&self) -> f64 {
        self.distance_m
    }

    /// One control step: from the odometry pose, sonar and laser of time
    /// `t_s` (and whether the last move bumped), the command to apply.
    pub fn update(
        &mut self,
        t_s: f64,
        odom: &Pose2,
        sonar: &SonarReading,
        laser: &LaserScan,
        bumped: bool,
    ) -> Command {
        self.remember(odom, laser);
        if bumped {
            self.recover_until_s = t_s + RECOVER_S;
        }
        let s = self.side.sign();
        if t_s < self.recover_until_s {
            self.mode = FollowerMode::Recover;
            return Command {
                v_mps: -0.08,
                omega_radps: -0.4 * s,
            };
        }

        // Points in the robot frame.
        let frame = odom.frame();
        let pts: Vec<DVec2> = self.memory.iter().map(|&p| frame.to_local(p)).collect();

        // Right after an encounter only the remembered wall will do: if it
        // is out of sight, the Seek branch below heads back to it (falling
        // back on any nearer point here is how robots got captured by a
        // pillar next to the place where they met).
        let nearest = self.nearest_wall_point(t_s, &frame, &pts);
        if let Some((r, q)) = nearest {
            // Remember the wall we follow, as long as no encounter is on.
            if self.waiting_since_s.is_none() && t_s >= self.reacquire_until_s {
                let n = q / r.max(1e-6);
                let tangent_odom = DVec2::from_angle(odom.theta).rotate(DVec2::new(n.y, -n.x));
                self.wall_line = Some((odom.transform_point(q), tangent_odom));
            }
        }
        let dir = self.steer_by_wall(t_s, odom, sonar, nearest);

        // Other robots: is one coming at us in our lane?
        let robots: Vec<DVec2> = self
            .robots_seen
            .iter()
            .map(|&p| frame.to_local(p))
            .collect();
        let Some(dir) = self.steer_by_robots(t_s, odom, &robots, dir) else {
            return Command::default();
        };
        self.drive(&pts, &robots, dir)
    }

    /// The nearest remembered point (robot frame) on the follow side or
    /// straight ahead, with its distance; right after an encounter, only a
    /// point on the remembered wall.
    fn nearest_wall_point(
        &self,
        t_s: f64,
        frame: &PoseFrame,
        pts: &[DVec2],
    ) -> Option<(f64, DVec2)> {
        let s = self.side.sign();
        let on_wall_line = |q: DVec2| match self.wall_line {
            Some((a, d)) if t_s < self.reacquire_until_s => {
                crate::geom::cross(d, frame.to_parent(q) - a).abs() < WALL_LINE_TOLERANCE_M
            }
            _ => true,
        };
        let mut best: Option<(f64, DVec2)> = None;
        for &q in pts {
            if s * q.y < -0.05 || !on_wall_line(q) {
                continue;
            }
            let r = q.length();
            if r < MEMORY_RADIUS_M && best.is_none_or(|(rb, _)| r < rb) {
                best = Some((r, q));
            }
        }
        best
    }

    /// The heading (robot frame, unit) that follows the wall at `nearest`:
    /// along it, leaning in or out to hold the clearance; with no wall in
    /// sight, straight ahead or back to the wall left at an encounter.
    fn steer_by_wall(
        &mut self,
        t_s: f64,
        odom: &Pose2,
        sonar: &SonarReading,
        nearest: Option<(f64, DVec2)>,
    ) -> DVec2 {
        let s = self.side.sign();
        match nearest {
            None => {
                self.mode = FollowerMode::Seek;
                match self.wall_line {
                    // Just after an encounter the wall may be hidden behind
                    // the other robot: head back to where we left it.
                    Some((a, _)) if t_s < self.reacquire_until_s => {
                        odom.inverse_transform_point(a).normalize_or(DVec2::X)
                    }
                    _ => DVec2::X,
                }
            }
            Some((r_laser, q)) => {
                let n = q / r_laser.max(1e-6);
                // Abeam: use the side sonar, as the thesis does.
                let bearing = n.y.atan2(n.x);
                let side_i = Self::side_sonar_index(self.side);
                let side_bearing = SONAR_BEARINGS_DEG[side_i].to_radians();
                let r_sonar = sonar.ranges_m[side_i] + SONAR_POSITIONS_M[side_i][1].abs();
                // The sonar also hears robots and sees through nothing the
                // laser missed: trust it only where the two agree.
                let r = if (bearing - side_bearing).abs() < 0.35
                    && !sonar.no_echo[side_i]
                    && (r_sonar - r_laser).abs() < 0.15
                {
                    r_sonar
                } else {
                    r_laser
                };
                let tangent = DVec2::new(s * n.y, -s * n.x);
                let lean = (LEAN_GAIN * (r - self.centre_distance_m)).clamp(-1.0, 1.0);
                self.mode = FollowerMode::Follow;
                (tangent + lean * n).normalize_or(DVec2::X)
            }
        }
    }

    /// Encounters with other robots (`robots`, robot frame): with one
    /// closing in our lane, the right-follower waits (`None`: stand still)
    /// and then, like the left-follower, goes around it; the heading `dir`
    /// is changed only while passing.
    fn steer_by_robots(
        &mut self,
        t_s: f64,
        odom: &Pose2,
        robots: &[DVec2],
        mut dir: DVec2,
    ) -> Option<DVec2> {
        let centroid = (!self.robots_seen.is_empty()).then(|| {
            self.robots_seen.iter().copied().sum::<DVec2>() / self.robots_seen.len() as f64
        });
        let closing_or_still = match (centroid, self.last_robot_centroid) {
            // The other robot's displacement along our heading over one step.
            (Some(c), Some(c0)) => (c - c0).dot(odom.heading()) < 0.01,
            _ => true,
        };
        self.last_robot_centroid = centroid;
        let in_lane = robots
            .iter()
            .any(|q| q.x > 0.0 && q.x < LANE_AHEAD_M && q.y.abs() < LANE_HALF_WIDTH_M);
        if in_lane && closing_or_still {
            let since = *self.waiting_since_s.get_or_insert(t_s);
            let yields = self.side == FollowSide::Right;
            if yields && t_s - since < MAX_WAIT_S {
                self.mode = FollowerMode::Yield;
                return None;
            }
            // Go around it: follow its body as a wall on our left (our right
            // is free), or, after waiting in vain, on our right.
            let around = if yields { -1.0 } else { 1.0 };
            if let Some(&q) = robots
                .iter()
                .min_by(|a, b| a.length_squared().total_cmp(&b.length_squared()))
            {
                let r = q.length().max(1e-6);
                let n = q / r;
                let tangent = DVec2::new(around * n.y, -around * n.x);
                let lean = (LEAN_GAIN * (r - PASSING_CLEARANCE_M)).clamp(-1.0, 1.0);
                dir = (tangent + lean * n).normalize_or(dir);
                self.mode = FollowerMode::Pass;
            }
        } else if self.waiting_since_s.take().is_some() {
            self.reacquire_until_s = t_s + REACQUIRE_S;
        }
        Some(dir)
    }

    /// The command that heads along `dir` (robot frame), pushed away from
    /// anything inside the body's personal space, slowing for turns and for
    /// obstacles in the swept corridor ahead.
    fn drive(&mut self, pts: &[DVec2], robots: &[DVec2], mut dir: DVec2) -> Command {
        let s = self.side.sign();
        // Push away from anything inside the body's personal space.
        let mut push = DVec2::ZERO;
        for &q in pts.iter().chain(robots) {
            let r = q.length();
            if r < PERSONAL_SPACE_M && r > 1e-6 {
                push -= q / r * ((PERSONAL_SPACE_M - r) / PERSONAL_SPACE_M) * 3.0;
            }
        }
        if push != DVec2::ZERO {
            dir = (dir + push).normalize_or(dir);
        }

        let psi = dir.y.atan2(dir.x);
        let omega = (TURN_GAIN * psi).clamp(-MAX_TURN_RATE, MAX_TURN_RATE);

        // Free space in the swept corridor ahead of the bumper.
        let half_w = 0.5 * P2dx::BODY_WIDTH_M + 0.08;
        let front = 0.5 * P2dx::BODY_LENGTH_M;
        let gap = pts
            .iter()
            .chain(robots)
            .filter(|q| q.x > 0.0 && q.y.abs() < half_w)
            .map(|q| q.x - front)
            .fold(f64::INFINITY, f64::min);
        let mut v = if psi.abs() > 1.2 {
            0.0
        } else {
            self.cruise_mps * psi.cos().max(0.0).powi(2)
        };
        v = v.min(0.8 * (gap - STOP_GAP_M)).max(0.0);
        if v < 0.02 && omega.abs() > 0.05 && self.mode == FollowerMode::Follow {
            self.mode = FollowerMode::Turn;
        }
        if v == 0.0 && omega.abs() < 0.05 {
            // Blocked straight ahead with nothing to steer by: turn away from
            // the follow side.
            return Command {
                v_mps: 0.0,
                omega_radps: -s * 0.8,
            };
        }
        Command {
            v_mps: v,
            omega_radps: omega,
        }
    }

    /// Replaces the remembered points in the scan's field of view with the
    /// current scan, keeping older points behind the robot and within reach.
    fn remember(&mut self, odom: &Pose2, laser: &LaserScan) {
        let frame = odom.frame();
        let tan_cover = SCAN_COVER_RAD.tan();
        let mut kept: Vec<DVec2> = self
            .memory
            .iter()
            .copied()
            .filter(|&p| {
                let q = frame.to_local(p);
                q.length() < MEMORY_RADIUS_M && outside_scan_cover(q, tan_cover)
            })
            .collect();
        self.robots_seen.clear();
        for i in 0..laser.ranges_m.len() {
            if laser.max_range[i] || laser.ranges_m[i] > MEMORY_RADIUS_M {
                continue;
            }
            let p = frame.to_parent(laser.point(i));
            if laser.reflective[i] {
                self.robots_seen.push(p);
            } else if i % 2 == 0 {
                kept.push(p);
            }
        }
        self.memory = kept;
    }
}

//! # What the page and the CLI ask of a robot's maps
//!
//! A separate `impl Lab` block (the session object is [`super::Lab`]): a
//! robot's map as ROS files or as a picture, its metadata, and the figures
//! that score it.
//! Scoring reads the truth, as display and scoring may; the mappers never do.

use super::Lab;
use crate::sim::{RobotSim, Simulation};
use crate::slam::eval::scoring::{ate_aligned_m, ate_m, map_accuracy, position_errors_m};
use crate::slam::export::{to_pgm, to_png, to_yaml, GridPicture};
use crate::slam::grid::OccupancyGrid;
use crate::slam::mapper::{MapperKind, RobotMapping};
use glam::DVec2;
use serde::Serialize;

/// The figures of one robot's two mappers (the report's `robots[].slam`).
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct SlamFigures {
    /// ATE of the SLAM poses (m).
    pub ate_m: f64,
    /// The same after the best rigid fit onto the truth (m): without the
    /// heading error made before anything was in view
    /// ([`crate::slam::eval::scoring`]).
    pub ate_aligned_m: f64,
    /// ATE of the raw odometry (m).
    pub odometry_ate_m: f64,
    /// Position error at the last step (m).
    pub final_error_m: f64,
    pub odometry_final_error_m: f64,
    /// Share of the SLAM map's occupied cells within 0.15 m of a true wall.
    pub occupied_precision: f64,
    pub odometry_occupied_precision: f64,
    /// Share of true wall length the SLAM map shows.
    pub wall_coverage: f64,
    pub odometry_wall_coverage: f64,
    pub occupied_cells: usize,
    /// Steps matched fully, across a corridor only, or left to odometry.
    pub matched_steps: usize,
    pub degenerate_steps: usize,
    pub odometry_only_steps: usize,
    /// Loop closures the back end accepted (each moved the trajectory and,
    /// where a key moved by more than a cell, redrew the map).
    pub loop_closures: usize,
    /// Cells of the SLAM grid and their bytes.
    pub map_width: usize,
    pub map_height: usize,
    pub map_bytes: usize,
}

fn r6(x: f64) -> f64 {
    (x * 1e6).round() / 1e6
}

/// Scores one robot of a simulation.
pub fn figures(sim: &Simulation, robot: &RobotSim) -> SlamFigures {
    let start = robot.spec.start_pose();
    let m: &RobotMapping = &robot.mapping;
    let truth = &robot.log.truth;
    let est = m.estimates();
    let slam = map_accuracy(&m.slam_map, &start, &sim.world);
    let odo = map_accuracy(&m.odometry_map, &start, &sim.world);
    let last_err = |poses: &[crate::geom::Pose2]| {
        let n = poses.len().min(truth.len());
        if n == 0 {
            0.0
        } else {
            (start.compose(&poses[n - 1]).position() - truth[n - 1].position()).length()
        }
    };
    SlamFigures {
        ate_m: r6(ate_m(&start, est, truth)),
        ate_aligned_m: r6(ate_aligned_m(&start, est, truth)),
        odometry_ate_m: r6(ate_m(&start, &robot.log.odometry, truth)),
        final_error_m: r6(last_err(est)),
        odometry_final_error_m: r6(last_err(&robot.log.odometry)),
        occupied_precision: r6(slam.occupied_precision),
        odometry_occupied_precision: r6(odo.occupied_precision),
        wall_coverage: r6(slam.wall_coverage),
        odometry_wall_coverage: r6(odo.wall_coverage),
        occupied_cells: slam.occupied_cells,
        matched_steps: m.counts.matched,
        degenerate_steps: m.counts.degenerate,
        loop_closures: m.graph.as_ref().map_or(0, |g| g.stats.closures_accepted),
        odometry_only_steps: m.counts.odometry_only,
        map_width: m.slam_map.width(),
        map_height: m.slam_map.height(),
        map_bytes: m.slam_map.memory_bytes(),
    }
}

/// Map metadata for the page (defined beside the grids, which the log
/// replay reports too).
pub use crate::slam::export::MapInfo;

/// Position error over time for the page's plot: every `stride`-th step,
/// `[t, slam_error_m, odometry_error_m]`.
#[derive(Serialize)]
pub struct ErrorSeries {
    pub rows: Vec<[f64; 3]>,
}

impl Lab {
    /// Re-matches robot `robot`'s latest scan against its SLAM map from
    /// the current prior, without changing anything (for timing the
    /// matcher); returns the matched pose.
    pub fn bench_match_scan(&self, robot: usize) -> Result<crate::geom::Pose2, String> {
        let sim = self
            .simulation()
            .ok_or("nothing has run yet: run the scenario first")?;
        let r = sim
            .robots
            .get(robot)
            .ok_or_else(|| format!("no robot with index {robot}"))?;
        let m = &r.mapping;
        let out =
            crate::slam::mapper::match_scan(&m.slam_map, &r.last_scan, &m.estimate(), &m.config);
        Ok(out.pose)
    }

    fn robot_sim(&self, robot: usize) -> Result<(&Simulation, &RobotSim), String> {
        let sim = self
            .simulation()
            .ok_or("nothing has run yet: run the scenario first")?;
        let r = sim
            .robots
            .get(robot)
            .ok_or_else(|| format!("no robot with index {robot}"))?;
        Ok((sim, r))
    }

    /// One robot's map (`which` = slam or odometry), whole: while the
    /// back end is redrawing it after a loop closure, a completed copy
    /// ([`crate::slam::RobotMapping::settled_map`]), so that a map exported
    /// from a paused run has every scan in it.
    pub fn robot_map(
        &self,
        robot: usize,
        which: MapperKind,
    ) -> Result<std::borrow::Cow<'_, OccupancyGrid>, String> {
        Ok(self.robot_sim(robot)?.1.mapping.settled_map(which))
    }

    /// Index of the robot called `name`.
    pub fn robot_index(&self, name: &str) -> Result<usize, String> {
        self.scenario()
            .robots
            .iter()
            .position(|r| r.name == name)
            .ok_or_else(|| format!("robot: no robot named '{name}'"))
    }

    pub fn map_pgm(&self, robot: usize, which: MapperKind) -> Result<Vec<u8>, String> {
        Ok(to_pgm(&*self.robot_map(robot, which)?))
    }

    pub fn map_png(&self, robot: usize, which: MapperKind) -> Result<Vec<u8>, String> {
        to_png(&*self.robot_map(robot, which)?)
    }

    pub fn map_yaml(&self, robot: usize, which: MapperKind, image: &str) -> Result<String, String> {
        Ok(to_yaml(&*self.robot_map(robot, which)?, image))
    }

    pub fn map_info(&self, robot: usize, which: MapperKind) -> Result<MapInfo, String> {
        Ok(MapInfo::of(&*self.robot_map(robot, which)?))
    }

    pub fn slam_figures(&self, robot: usize) -> Result<SlamFigures, String> {
        let (sim, r) = self.robot_sim(robot)?;
        Ok(figures(sim, r))
    }

    /// Position errors over time, at most about `max_rows` rows.
    pub fn slam_errors(&self, robot: usize, max_rows: usize) -> Result<ErrorSeries, String> {
        let (_, r) = self.robot_sim(robot)?;
        let start = r.spec.start_pose();
        let e = position_errors_m(&start, r.mapping.estimates(), &r.log.truth);
        let o = position_errors_m(&start, &r.log.odometry, &r.log.truth);
        let n = e.len().min(o.len()).min(r.log.times_s.len());
        let stride = n.div_ceil(max_rows.max(1)).max(1);
        let rows = (0..n)
            .step_by(stride)
            .map(|k| [r.log.times_s[k], r6(e[k]), r6(o[k])])
            .collect();
        Ok(ErrorSeries { rows })
    }

    /// Draws one robot's map as RGBA pixels (`width × height`, straight
    /// alpha, opaque), fitted to the image, with the SLAM (or odometry)
    /// path and the true path (drawn in the odometry frame) on top.
    pub fn map_rgba(
        &self,
        robot: usize,
        which: MapperKind,
        width: u32,
        height: u32,
    ) -> Result<Vec<u8>, String> {
        let (_, r) = self.robot_sim(robot)?;
        let g = r.mapping.map(which);
        let mut pic = GridPicture::new(g, width, height)?;
        if g.width() == 0 {
            return Ok(pic.into_rgba());
        }
        let inv_start = r.spec.start_pose().inverse();
        let truth: Vec<DVec2> = r
            .log
            .truth
            .iter()
            .map(|t| inv_start.compose(t).position())
            .collect();
        let est: &[crate::geom::Pose2] = match which {
            MapperKind::Slam => r.mapping.estimates(),
            MapperKind::Odometry => &r.log.odometry,
        };
        let est: Vec<DVec2> = est.iter().map(|p| p.position()).collect();
        pic.polyline(&truth, [40, 160, 60, 255], 1.5);
        pic.polyline(&est, [200, 40, 40, 255], 1.5);
        Ok(pic.into_rgba())
    }
}

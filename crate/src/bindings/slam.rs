//! # JavaScript boundary of the SLAM maps
//!
//! A second `#[wasm_bindgen] impl Lab` block: a robot's map (`"slam"` or
//! `"odometry"`) as pixels, metadata, ROS map_server files, and the figures
//! and error series the page plots. Robots are addressed by index (the
//! order of the scenario's `robots`); `robotIndex(name)` looks one up.

use super::convert::{js_err as err, put_rgba, to_json};
use super::Lab;
use crate::lab::mapping_away::MappingAway;
use crate::lab::MapperKind;
use wasm_bindgen::prelude::*;

fn kind(mapper: &str) -> Result<MapperKind, JsError> {
    MapperKind::parse(mapper).map_err(err)
}

#[wasm_bindgen]
impl Lab {
    /// Index of the robot called `name`; throws if there is none.
    #[wasm_bindgen(js_name = robotIndex)]
    pub fn robot_index(&self, name: &str) -> Result<u32, JsError> {
        Ok(self.inner.robot_index(name).map_err(err)? as u32)
    }

    /// The map as a binary PGM (ROS map_server: free 254, occupied 0,
    /// unknown 205, row 0 at the top).
    #[wasm_bindgen(js_name = mapPgm)]
    pub fn map_pgm(&self, robot: u32, mapper: &str) -> Result<Vec<u8>, JsError> {
        self.inner
            .map_pgm(robot as usize, kind(mapper)?)
            .map_err(err)
    }

    /// The same pixels as a PNG.
    #[wasm_bindgen(js_name = mapPng)]
    pub fn map_png(&self, robot: u32, mapper: &str) -> Result<Vec<u8>, JsError> {
        self.inner
            .map_png(robot as usize, kind(mapper)?)
            .map_err(err)
    }

    /// The map_server YAML naming `image` (the PGM's file name).
    #[wasm_bindgen(js_name = mapYaml)]
    pub fn map_yaml(&self, robot: u32, mapper: &str, image: &str) -> Result<String, JsError> {
        self.inner
            .map_yaml(robot as usize, kind(mapper)?, image)
            .map_err(err)
    }

    /// Size, resolution and origin of a map (JSON).
    #[wasm_bindgen(js_name = mapInfoJson)]
    pub fn map_info_json(&self, robot: u32, mapper: &str) -> Result<String, JsError> {
        let info = self
            .inner
            .map_info(robot as usize, kind(mapper)?)
            .map_err(err)?;
        to_json(&info)
    }

    /// ATE and map figures of one robot (JSON, as in the report).
    #[wasm_bindgen(js_name = slamFiguresJson)]
    pub fn slam_figures_json(&self, robot: u32) -> Result<String, JsError> {
        let f = self.inner.slam_figures(robot as usize).map_err(err)?;
        to_json(&f)
    }

    /// Position error over time, `{"rows": [[t, slam_m, odometry_m], ...]}`,
    /// at most about `max_rows` rows.
    #[wasm_bindgen(js_name = slamErrorsJson)]
    pub fn slam_errors_json(&self, robot: u32, max_rows: u32) -> Result<String, JsError> {
        let s = self
            .inner
            .slam_errors(robot as usize, max_rows as usize)
            .map_err(err)?;
        to_json(&s)
    }

    /// Draws a robot's map with its estimated (red) and true (green) paths
    /// into a 2-D canvas context of `width × height`.
    #[wasm_bindgen(js_name = drawMap)]
    pub fn draw_map(
        &self,
        ctx: &web_sys::CanvasRenderingContext2d,
        robot: u32,
        mapper: &str,
        width: u32,
        height: u32,
    ) -> Result<(), JsError> {
        let px = self
            .inner
            .map_rgba(robot as usize, kind(mapper)?, width, height)
            .map_err(err)?;
        put_rgba(ctx, &px, width, height)
    }

    /// Re-matches robot `robot`'s latest scan against its SLAM map from the
    /// current prior, without changing anything (for timing the matcher).
    /// Returns the matched pose `[x, y, theta]`.
    #[wasm_bindgen(js_name = benchMatchScan)]
    pub fn bench_match_scan(&self, robot: u32) -> Result<Vec<f64>, JsError> {
        let pose = self.inner.bench_match_scan(robot as usize).map_err(err)?;
        Ok(vec![pose.x, pose.y, pose.theta])
    }

    /// Hands robot `robot`'s mapping to another thread: its bytes, for a
    /// `SlamAway` there. From now on the robot's steps wait for
    /// `takeMappingSteps` instead of being mapped here, until
    /// `bringMappingHome`.
    #[wasm_bindgen(js_name = sendMappingAway)]
    pub fn send_mapping_away(&mut self, robot: u32) -> Result<Vec<u8>, JsError> {
        self.inner.send_mapping_away(robot as usize).map_err(err)
    }

    /// The steps robot `robot`'s mapping, away, has yet to be sent, packed
    /// for `SlamAway.observe` (empty when its mapping is here).
    #[wasm_bindgen(js_name = takeMappingSteps)]
    pub fn take_mapping_steps(&mut self, robot: u32) -> Vec<u8> {
        self.inner.take_mapping_steps(robot as usize)
    }

    /// Appends the SLAM poses robot `robot`'s mapping, away, reports for
    /// its newest steps (`SlamAway.estimatesFrom`), which the choice of
    /// frames to describe meanwhile reads.
    #[wasm_bindgen(js_name = noteAwayEstimates)]
    pub fn note_away_estimates(&mut self, robot: u32, flat: &[f64]) -> Result<(), JsError> {
        self.inner
            .note_away_estimates(robot as usize, flat)
            .map_err(err)
    }

    /// Takes robot `robot`'s mapping back (`SlamAway.finish`'s bytes); it
    /// must have been sent every step of the run so far.
    #[wasm_bindgen(js_name = bringMappingHome)]
    pub fn bring_mapping_home(&mut self, robot: u32, bytes: &[u8]) -> Result<(), JsError> {
        self.inner
            .bring_mapping_home(robot as usize, bytes)
            .map_err(err)
    }
}

/// A robot's mapping on another thread (`web/cli/slam-pool.mjs`): made
/// from `Lab.sendMappingAway`'s bytes, fed `Lab.takeMappingSteps`'s
/// batches in order, and sent home as bytes for `Lab.bringMappingHome`
/// ([`crate::lab::mapping_away`]).
#[wasm_bindgen]
pub struct SlamAway {
    inner: MappingAway,
}

#[wasm_bindgen]
impl SlamAway {
    #[wasm_bindgen(constructor)]
    pub fn new(bytes: &[u8]) -> Result<SlamAway, JsError> {
        Ok(SlamAway {
            inner: MappingAway::new(bytes).map_err(err)?,
        })
    }

    /// Maps a batch of steps; returns how many it held. A batch cut short
    /// throws and maps none of its steps.
    pub fn observe(&mut self, steps: &[u8]) -> Result<u32, JsError> {
        Ok(self.inner.observe(steps).map_err(err)? as u32)
    }

    /// Steps mapped so far (the run's, from its start).
    pub fn steps(&self) -> u32 {
        self.inner.steps() as u32
    }

    /// The estimates from row `row` on (row 0 is the start), flat
    /// `[x, y, theta, …]`, for `Lab.noteAwayEstimates`.
    #[wasm_bindgen(js_name = estimatesFrom)]
    pub fn estimates_from(&self, row: u32) -> Vec<f64> {
        self.inner.estimates_from(row as usize)
    }

    /// The mapping as bytes, for `Lab.bringMappingHome`.
    pub fn finish(&self) -> Result<Vec<u8>, JsError> {
        self.inner.finish().map_err(err)
    }
}

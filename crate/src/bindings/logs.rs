//! # JavaScript boundary of the log replay
//!
//! `LogReplay` wraps the log replay session ([`crate::lab::log_replay`]):
//! open a CARMEN log from its bytes (plain or gzip), optionally restrict it
//! to a stretch of laser records, replay it a few scans at a time, finish,
//! then read the report (JSON) and the map (ROS map_server PGM + YAML,
//! PNG). Converts only.

use super::convert::{js_err as err, to_json};
use crate::lab::log_replay;
use wasm_bindgen::prelude::*;

#[wasm_bindgen]
pub struct LogReplay {
    inner: log_replay::LogReplay,
}

impl LogReplay {
    /// Wraps a session made elsewhere (a bag's replay).
    pub(super) fn wrap(inner: log_replay::LogReplay) -> LogReplay {
        LogReplay { inner }
    }
}

#[wasm_bindgen]
impl LogReplay {
    /// Parses the log; throws with the line number on a malformed record.
    #[wasm_bindgen(constructor)]
    pub fn new(bytes: &[u8]) -> Result<LogReplay, JsError> {
        Ok(LogReplay {
            inner: log_replay::LogReplay::new(bytes).map_err(err)?,
        })
    }

    /// Number of laser records in the log.
    #[wasm_bindgen(js_name = laserRecords)]
    pub fn laser_records(&self) -> u32 {
        self.inner.laser_records() as u32
    }

    /// What was picked from a bag and why (JSON; `null` for a CARMEN log):
    /// the scan topic, the odometry, the ground truth, the laser's offset,
    /// and the other topics there were to pick.
    #[wasm_bindgen(js_name = pickedJson)]
    pub fn picked_json(&self) -> Result<String, JsError> {
        to_json(&self.inner.picked())
    }

    /// Replays laser records `from..=to` only (`to` < 0: to the end).
    #[wasm_bindgen(js_name = setRange)]
    pub fn set_range(&mut self, from: u32, to: i32) -> Result<(), JsError> {
        let to = usize::try_from(to).ok();
        self.inner.set_range(from as usize, to).map_err(err)
    }

    /// Replays up to `n` more scans; returns how many are left.
    pub fn step(&mut self, n: u32) -> u32 {
        self.inner.step(n as usize) as u32
    }

    /// Replays what is left, settles the pose graph and draws the map.
    pub fn finish(&mut self) -> Result<(), JsError> {
        self.inner.finish().map_err(err)
    }

    /// The run-log report (JSON); `timings_json` becomes its `timings_ms`.
    #[wasm_bindgen(js_name = reportJson)]
    pub fn report_json(&self, timings_json: &str) -> Result<String, JsError> {
        let timings: serde_json::Value = serde_json::from_str(timings_json).map_err(err)?;
        to_json(&self.inner.report(timings).map_err(err)?)
    }

    /// The map as a binary PGM (ROS map_server).
    #[wasm_bindgen(js_name = mapPgm)]
    pub fn map_pgm(&self) -> Result<Vec<u8>, JsError> {
        self.inner.map_pgm().map_err(err)
    }

    /// The map as a PNG.
    #[wasm_bindgen(js_name = mapPng)]
    pub fn map_png(&self) -> Result<Vec<u8>, JsError> {
        self.inner.map_png().map_err(err)
    }

    /// The map_server YAML naming `image` (the PGM's file name).
    #[wasm_bindgen(js_name = mapYaml)]
    pub fn map_yaml(&self, image: &str) -> Result<String, JsError> {
        self.inner.map_yaml(image).map_err(err)
    }

    /// The replay so far, for a page that animates it (JSON): `done` and
    /// `total` scans, each replayed scan's odometry and current SLAM pose
    /// as flat `[x, y, theta, ...]` lists, and each loop closure found so
    /// far as the segment between its two key scans' current poses
    /// (`[x1, y1, x2, y2]`), with its scan indices and score.
    #[wasm_bindgen(js_name = viewJson)]
    pub fn view_json(&self) -> Result<String, JsError> {
        to_json(&self.inner.view())
    }

    /// The ground truth beside the SLAM path so far (JSON `{poses, errors,
    /// ate_m}`: the truth laid onto the SLAM's frame by the ATE's rigid fit,
    /// flat `[x, y, theta, ...]`, and `[time, error m, ...]`), or `null`
    /// when the log has none.
    #[wasm_bindgen(js_name = truthJson)]
    pub fn truth_json(&self) -> Result<String, JsError> {
        to_json(&self.inner.truth_view())
    }

    /// Sets the relations of a benchmark file (`t1 t2 x y z roll pitch
    /// yaw` lines) to score against: the report gets `relations`. Returns
    /// how many; throws naming a malformed line.
    #[wasm_bindgen(js_name = setRelations)]
    pub fn set_relations(&mut self, text: &str) -> Result<u32, JsError> {
        Ok(self.inner.set_relations(text).map_err(err)? as u32)
    }

    /// Whether the report also checks the relations against their own
    /// scans and the wheel odometry (its `relation_check`; `run-log
    /// --check-relations`).
    #[wasm_bindgen(js_name = setCheckRelations)]
    pub fn set_check_relations(&mut self, on: bool) {
        self.inner.set_check_relations(on);
    }

    /// The relations set checked against their own scans and the wheel
    /// odometry (JSON, as `run-log --check-relations` reports
    /// `relation_check`), or `null` without relations. Aligns two scans per
    /// relation: a few seconds for a benchmark log.
    #[wasm_bindgen(js_name = relationCheckJson)]
    pub fn relation_check_json(&self) -> Result<String, JsError> {
        to_json(&self.inner.relation_check())
    }

    /// The replay so far scored against the relations set (JSON `{count,
    /// matched, trans_m: {mean, sd, max}, rot_deg: {…}, worst: […],
    /// errors: […]}`).
    #[wasm_bindgen(js_name = relationScoreJson)]
    pub fn relation_score_json(&self) -> Result<String, JsError> {
        to_json(&self.inner.relation_score())
    }

    /// Draws the map of the scans replayed so far at their current poses
    /// (kept for `liveInfoJson` and `livePixels`); returns false before
    /// the first scan.
    #[wasm_bindgen(js_name = drawLive)]
    pub fn draw_live(&mut self) -> bool {
        self.inner.draw_live()
    }

    /// Each scan's time (s, the log's clock) of the stretch replayed,
    /// replayed or not: a timeline.
    pub fn times(&self) -> Vec<f64> {
        self.inner.times()
    }

    /// The replay as it was once `k` scans were replayed (JSON, as
    /// `viewJson`): the first `k` scans at the poses the SLAM had for them
    /// then, and the loop closures found by then. Throws unless
    /// `1 <= k <=` the scans replayed.
    #[wasm_bindgen(js_name = viewAtJson)]
    pub fn view_at_json(&self, k: u32) -> Result<String, JsError> {
        to_json(&self.inner.view_at(k as usize).map_err(err)?)
    }

    /// Draws the map of the first `k` scans at the poses they had once
    /// scan `k` was replayed, as the live map (`liveInfoJson`,
    /// `livePixels`). Throws unless `1 <= k <=` the scans replayed.
    #[wasm_bindgen(js_name = drawAt)]
    pub fn draw_at(&mut self, k: u32) -> Result<(), JsError> {
        self.inner.draw_at(k as usize).map_err(err)
    }

    /// Size, resolution and origin of the live map (`MapInfo` JSON).
    #[wasm_bindgen(js_name = liveInfoJson)]
    pub fn live_info_json(&self) -> Result<String, JsError> {
        to_json(&self.inner.live_info().map_err(err)?)
    }

    /// The live map's grey pixels (PGM shades), top row first.
    #[wasm_bindgen(js_name = livePixels)]
    pub fn live_pixels(&self) -> Result<Vec<u8>, JsError> {
        self.inner.live_pixels().map_err(err)
    }
}

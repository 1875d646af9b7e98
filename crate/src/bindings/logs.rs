//! # JavaScript boundary of the log replay
//!
//! `LogReplay` wraps [`crate::slam::log_replay::LogReplay`]: open a CARMEN
//! log from its bytes (plain or gzip), optionally restrict it to a stretch of
//! laser records, replay it a few scans at a time, finish, then read the
//! report (JSON) and the map (ROS map_server PGM + YAML, PNG).

use crate::slam::export;
use crate::slam::log_replay;
use wasm_bindgen::prelude::*;

use super::convert::js_err as err;

#[wasm_bindgen]
pub struct LogReplay {
    inner: log_replay::LogReplay,
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
        let report = self.inner.report(timings).map_err(err)?;
        serde_json::to_string(&report).map_err(err)
    }

    /// The map as a binary PGM (ROS map_server).
    #[wasm_bindgen(js_name = mapPgm)]
    pub fn map_pgm(&self) -> Result<Vec<u8>, JsError> {
        Ok(export::to_pgm(self.inner.map().map_err(err)?))
    }

    /// The map as a PNG.
    #[wasm_bindgen(js_name = mapPng)]
    pub fn map_png(&self) -> Result<Vec<u8>, JsError> {
        export::to_png(self.inner.map().map_err(err)?).map_err(err)
    }

    /// The map_server YAML naming `image` (the PGM's file name).
    #[wasm_bindgen(js_name = mapYaml)]
    pub fn map_yaml(&self, image: &str) -> Result<String, JsError> {
        Ok(export::to_yaml(self.inner.map().map_err(err)?, image))
    }
}

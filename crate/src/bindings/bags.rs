//! # JavaScript boundary of the bag session
//!
//! `BagFile` wraps [`crate::lab::bag_file::BagFile`]: the caller pushes a
//! bag's files in pieces (`beginFile`, `push`, `endFile`; a rosbag2
//! folder's `metadata.yaml` first with `setMetadata`), then `finish`
//! returns what `bag-info` prints, and `replay` makes a `LogReplay` of the
//! picked scans. Converts only.

use super::convert::{js_err as err, to_json};
use super::logs::LogReplay;
use crate::lab::bag_file::{self, Picks};
use wasm_bindgen::prelude::*;

#[wasm_bindgen]
pub struct BagFile {
    pub(super) inner: bag_file::BagFile,
}

/// What the page and the CLI may ask of a bag's log (JSON): `scan_topic`,
/// `odom_topic` (`"tf"`: the moving transform of `/tf`), `odom_none`,
/// `truth_topic`, `truth_none`, each optional.
#[derive(serde::Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct PicksJson {
    scan_topic: Option<String>,
    odom_topic: Option<String>,
    #[serde(default)]
    odom_none: bool,
    truth_topic: Option<String>,
    #[serde(default)]
    truth_none: bool,
}

/// Which container a file is from its first bytes (16 are enough):
/// `"ros1"`, `"mcap"`, `"sqlite"`, or `""` when none.
#[wasm_bindgen(js_name = bagKind)]
pub fn bag_kind(first_bytes: &[u8]) -> String {
    bag_file::bag_kind(first_bytes).to_string()
}

#[wasm_bindgen]
impl BagFile {
    /// A bag called `name` (a file's or a rosbag2 folder's name).
    #[wasm_bindgen(constructor)]
    pub fn new(name: &str) -> BagFile {
        BagFile {
            inner: bag_file::BagFile::new(name),
        }
    }

    /// A rosbag2 folder's `metadata.yaml` text (before its data files).
    #[wasm_bindgen(js_name = setMetadata)]
    pub fn set_metadata(&mut self, yaml: &str) -> Result<(), JsError> {
        self.inner.set_metadata(yaml).map_err(err)
    }

    /// The data files the metadata lists, in order (JSON array).
    #[wasm_bindgen(js_name = metadataFilesJson)]
    pub fn metadata_files_json(&self) -> Result<String, JsError> {
        to_json(&self.inner.metadata_files())
    }

    /// Starts the next file of the bag.
    #[wasm_bindgen(js_name = beginFile)]
    pub fn begin_file(&mut self, name: &str) -> Result<(), JsError> {
        self.inner.begin_file(name).map_err(err)
    }

    /// The current file's next bytes, in order.
    pub fn push(&mut self, bytes: &[u8]) -> Result<(), JsError> {
        self.inner.push(bytes).map_err(err)
    }

    /// Ends the current file.
    #[wasm_bindgen(js_name = endFile)]
    pub fn end_file(&mut self) -> Result<(), JsError> {
        self.inner.end_file().map_err(err)
    }

    /// The bag has been read; returns its info (JSON, as `bag-info --json`).
    pub fn finish(&mut self) -> Result<String, JsError> {
        to_json(&self.inner.finish().map_err(err)?)
    }

    /// The info again (JSON).
    #[wasm_bindgen(js_name = infoJson)]
    pub fn info_json(&self) -> Result<String, JsError> {
        to_json(&self.inner.info())
    }

    /// A replay of the bag's scans; `picks_json` as `PicksJson` above.
    pub fn replay(&self, picks_json: &str) -> Result<LogReplay, JsError> {
        let p: PicksJson = if picks_json.trim().is_empty() {
            PicksJson::default()
        } else {
            serde_json::from_str(picks_json).map_err(|e| err(format!("picks: {e}")))?
        };
        let picks = Picks {
            scan_topic: p.scan_topic,
            odom_topic: p.odom_topic,
            odom_none: p.odom_none,
            truth_topic: p.truth_topic,
            truth_none: p.truth_none,
        };
        Ok(LogReplay::wrap(self.inner.replay(&picks).map_err(err)?))
    }
}

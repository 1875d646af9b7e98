//! # JavaScript boundary of the saved-maps merge
//!
//! `MapMerge` holds the saved maps a user brought (ROS `map_server` YAML
//! text and image bytes, read by the caller: node from disk, the page from
//! a file picker), merges them ([`crate::merge::saved`]) and hands back
//! the report as JSON and the merged map as PGM, PNG and YAML. A thin
//! converting layer: every error is a `JsError` whose message names the
//! file and the field.

use super::convert::js_err as err;
use crate::formats::rosmap::{self, write::MergedMap, MapYaml, RosMap};
use crate::geom::Pose2;
use crate::merge::saved::refine::{refine_pair, refuse_if_beaten};
use crate::merge::saved::wallmap::WallMap;
use crate::merge::saved::{merge_all, PairResult, SavedMerge, SavedMergeConfig};
use wasm_bindgen::prelude::*;

/// Saved maps and, after `merge`, the result.
#[wasm_bindgen]
#[derive(Default)]
pub struct MapMerge {
    maps: Vec<RosMap>,
    result: Option<SavedMerge>,
    /// The automatic merge's pairs, kept for Refine's check.
    automatic: Vec<PairResult>,
    merged: Option<MergedMap>,
}

/// The `image` field of a map YAML (the path of its image, relative to the
/// YAML's folder), so the caller knows which file to read.
#[wasm_bindgen(js_name = mapImagePath)]
pub fn map_image_path(name: &str, yaml_text: &str) -> Result<String, JsError> {
    Ok(MapYaml::parse(name, yaml_text).map_err(err)?.image)
}

/// The most cells a map may hold.
#[wasm_bindgen(js_name = mapMaxCells)]
pub fn map_max_cells() -> u32 {
    rosmap::MAX_CELLS as u32
}

#[wasm_bindgen]
impl MapMerge {
    #[wasm_bindgen(constructor)]
    pub fn new() -> MapMerge {
        MapMerge::default()
    }

    /// Reads one map (`name`: the YAML's path as given; `image_name`: the
    /// image's path, for messages). Returns its index.
    #[wasm_bindgen(js_name = addMap)]
    pub fn add_map(
        &mut self,
        name: &str,
        yaml_text: &str,
        image_name: &str,
        image: &[u8],
    ) -> Result<u32, JsError> {
        if self.maps.len() >= 16 {
            return Err(JsError::new(&format!(
                "{name}: at most 16 maps can be merged at once"
            )));
        }
        let map = rosmap::load(name, yaml_text, image_name, image).map_err(err)?;
        self.maps.push(map);
        self.result = None;
        self.merged = None;
        Ok(self.maps.len() as u32 - 1)
    }

    /// Size, resolution and origin of map `i` (JSON `{name, width, height,
    /// resolution, origin: [x, y, yaw]}`).
    #[wasm_bindgen(js_name = mapInfoJson)]
    pub fn map_info_json(&self, i: u32) -> Result<String, JsError> {
        let m = self
            .maps
            .get(i as usize)
            .ok_or_else(|| JsError::new("no such map"))?;
        let o = m.origin;
        Ok(serde_json::json!({"name": m.name, "width": m.width, "height": m.height, "resolution": m.resolution, "origin": [o.x, o.y, o.theta]}).to_string())
    }

    /// Map `i`'s cells as grey values for drawing, top row first (PGM
    /// shades: free 254, occupied 0, unknown 205, `scale` values graded
    /// between).
    #[wasm_bindgen(js_name = mapPixels)]
    pub fn map_pixels(&self, i: u32) -> Result<Vec<u8>, JsError> {
        let m = self
            .maps
            .get(i as usize)
            .ok_or_else(|| JsError::new("no such map"))?;
        let mut out = Vec::with_capacity(m.data.len());
        for row in m.data.chunks(m.width).rev() {
            out.extend(row.iter().map(|&v| match v {
                0..=100 => (254 - (v as i32 * 254) / 100) as u8,
                _ => 205,
            }));
        }
        Ok(out)
    }

    /// Merges the maps; returns the report's `maps` and `merge` as JSON.
    pub fn merge(&mut self) -> Result<String, JsError> {
        self.run_merge(&mut |_| {})
    }

    /// The same as `merge`, calling `progress` with a line of text after
    /// each pair (the page's worker forwards it as the merge's progress).
    #[wasm_bindgen(js_name = mergeWithProgress)]
    pub fn merge_with_progress(&mut self, progress: &js_sys::Function) -> Result<String, JsError> {
        self.run_merge(&mut |line: &str| {
            // A throwing callback only loses a progress line.
            let _ = progress.call1(&JsValue::NULL, &JsValue::from_str(line));
        })
    }

    fn run_merge(&mut self, progress: &mut dyn FnMut(&str)) -> Result<String, JsError> {
        if self.maps.len() < 2 {
            return Err(JsError::new("merge-maps needs at least two maps"));
        }
        let result = merge_all(&self.maps, &SavedMergeConfig::default(), progress);
        let report = result.report(&self.maps).to_string();
        self.automatic = result.pairs.clone();
        self.result = Some(result);
        self.merged = None;
        Ok(report)
    }

    fn merged(&mut self) -> Result<&MergedMap, JsError> {
        if self.merged.is_none() {
            let r = self
                .result
                .as_ref()
                .ok_or_else(|| JsError::new("merge first"))?;
            let joined: Vec<(&RosMap, crate::geom::Pose2)> = r
                .poses
                .iter()
                .zip(&self.maps)
                .filter_map(|(p, m)| p.map(|p| (m, p)))
                .collect();
            self.merged = Some(rosmap::write::merge_maps(&joined).map_err(err)?);
        }
        self.merged
            .as_ref()
            .ok_or_else(|| JsError::new("no merged map"))
    }

    /// Aligns maps `a` and `b` again from a person's rough overlay: map
    /// `b`'s frame at `(x, y, theta)` (metres, radians) in map `a`'s frame,
    /// as the report's transforms. The result replaces that pair's verdict
    /// and the maps are joined again, so the report (`reportJson`) and the
    /// merged map follow it. Returns the pair's result as JSON, in the
    /// report's `pairs[]` format (with `guess`). The pair is refined in the
    /// order the merge judged it, so for `a > b` it comes back as `b`, `a`
    /// with the guess inverted. A refined overlay is refused when the
    /// automatic merge found a different one with 1.5 times its support.
    pub fn refine(
        &mut self,
        a: u32,
        b: u32,
        x: f64,
        y: f64,
        theta: f64,
    ) -> Result<String, JsError> {
        let (a, b) = (a as usize, b as usize);
        let n = self.maps.len();
        if a >= n || b >= n || a == b {
            return Err(JsError::new(&format!(
                "refine: maps {a} and {b} are not a pair of the {n} maps opened"
            )));
        }
        let mut guess = Pose2::new(x, y, theta);
        if !guess.is_finite() {
            return Err(JsError::new(&format!(
                "refine: the guess must be finite numbers, got x = {x}, y = {y}, theta = {theta}"
            )));
        }
        let result = self
            .result
            .as_mut()
            .ok_or_else(|| JsError::new("refine: merge first"))?;
        // Refined in the order the merge judged the pair.
        let automatic = self
            .automatic
            .iter()
            .find(|p| (p.a, p.b) == (a, b) || (p.a, p.b) == (b, a))
            .ok_or_else(|| JsError::new("refine: that pair was not judged"))?;
        let (a, b) = if automatic.a == a {
            (a, b)
        } else {
            guess = guess.inverse();
            (b, a)
        };
        let cfg = SavedMergeConfig::default();
        let (ma, mb) = (&self.maps[a], &self.maps[b]);
        let (wa, wb) = (WallMap::new(ma), WallMap::new(mb));
        let mut pair = refine_pair((a, ma, &wa), (b, mb, &wb), guess, &cfg)
            .map_err(|e| JsError::new(&format!("refine: {e}")))?;
        refuse_if_beaten(&mut pair, automatic, (ma, mb), &cfg);
        let k = result
            .replace_pair(&self.maps, pair)
            .ok_or_else(|| JsError::new("refine: that pair was not judged"))?;
        self.merged = None;
        let report = result.report(&self.maps);
        Ok(report["merge"]["pairs"][k].to_string())
    }

    /// The report's `maps` and `merge` as JSON, as `merge` returned it,
    /// after any `refine`.
    #[wasm_bindgen(js_name = reportJson)]
    pub fn report_json(&self) -> Result<String, JsError> {
        let r = self
            .result
            .as_ref()
            .ok_or_else(|| JsError::new("merge first"))?;
        Ok(r.report(&self.maps).to_string())
    }

    /// The merged map (the maps joined to the first) as a binary PGM.
    #[wasm_bindgen(js_name = mergedPgm)]
    pub fn merged_pgm(&mut self) -> Result<Vec<u8>, JsError> {
        Ok(self.merged()?.pgm())
    }

    /// The same pixels as a PNG.
    #[wasm_bindgen(js_name = mergedPng)]
    pub fn merged_png(&mut self) -> Result<Vec<u8>, JsError> {
        self.merged()?.png().map_err(err)
    }

    /// The map_server YAML naming `image`.
    #[wasm_bindgen(js_name = mergedYaml)]
    pub fn merged_yaml(&mut self, image: &str) -> Result<String, JsError> {
        Ok(self.merged()?.yaml(image))
    }
}

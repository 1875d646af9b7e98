//! # JavaScript boundary of the saved-maps merge
//!
//! `MapMerge` wraps the saved-maps session ([`crate::lab::saved_maps`]):
//! map YAML text and image bytes in, the report as JSON and the merged map
//! as PGM, PNG and YAML out. Converts only: every error is a `JsError`
//! whose message names the file and the field.

use super::bags::BagFile;
use super::convert::{js_err as err, to_json};
use crate::lab::saved_maps::{self, SavedMaps};
use crate::lab::Pose2;
use wasm_bindgen::prelude::*;

/// Saved maps and, after `merge`, the result.
#[wasm_bindgen]
#[derive(Default)]
pub struct MapMerge {
    inner: SavedMaps,
}

/// The `image` field of a map YAML (the path of its image, relative to the
/// YAML's folder), so the caller knows which file to read.
#[wasm_bindgen(js_name = mapImagePath)]
pub fn map_image_path(name: &str, yaml_text: &str) -> Result<String, JsError> {
    saved_maps::map_image_path(name, yaml_text).map_err(err)
}

/// The most cells a map may hold.
#[wasm_bindgen(js_name = mapMaxCells)]
pub fn map_max_cells() -> u32 {
    saved_maps::max_cells() as u32
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
        let i = self
            .inner
            .add_map(name, yaml_text, image_name, image)
            .map_err(err)?;
        Ok(i as u32)
    }

    /// Reads a map in place of map `i` (same arguments as `addMap`); the
    /// other maps keep their indices.
    #[wasm_bindgen(js_name = replaceMap)]
    pub fn replace_map(
        &mut self,
        i: u32,
        name: &str,
        yaml_text: &str,
        image_name: &str,
        image: &[u8],
    ) -> Result<(), JsError> {
        self.inner
            .replace_map(i as usize, name, yaml_text, image_name, image)
            .map_err(err)
    }

    /// Adds the last map of a bag's `nav_msgs/OccupancyGrid` topic
    /// (`topic` empty: `/map`, else the bag's only map topic), named as the
    /// bag. Returns its index.
    #[wasm_bindgen(js_name = addBagMap)]
    pub fn add_bag_map(&mut self, bag: &BagFile, topic: &str) -> Result<u32, JsError> {
        let topic = (!topic.is_empty()).then_some(topic);
        let map = bag.inner.map(topic).map_err(err)?;
        Ok(self.inner.add_loaded(map).map_err(err)? as u32)
    }

    /// Size, resolution and origin of map `i` (JSON `{name, width, height,
    /// resolution, origin: [x, y, yaw]}`).
    #[wasm_bindgen(js_name = mapInfoJson)]
    pub fn map_info_json(&self, i: u32) -> Result<String, JsError> {
        to_json(&self.inner.map_info(i as usize).map_err(err)?)
    }

    /// Map `i`'s cells as grey values for drawing, top row first (PGM
    /// shades: free 254, occupied 0, unknown 205).
    #[wasm_bindgen(js_name = mapPixels)]
    pub fn map_pixels(&self, i: u32) -> Result<Vec<u8>, JsError> {
        self.inner.map_pixels(i as usize).map_err(err)
    }

    /// Merges the maps; returns the report's `maps` and `merge` as JSON.
    pub fn merge(&mut self) -> Result<String, JsError> {
        to_json(&self.inner.merge(&mut |_| {}).map_err(err)?)
    }

    /// The same as `merge`, calling `progress` with a line of text after
    /// each pair (the page's worker forwards it as the merge's progress).
    #[wasm_bindgen(js_name = mergeWithProgress)]
    pub fn merge_with_progress(&mut self, progress: &js_sys::Function) -> Result<String, JsError> {
        let report = self
            .inner
            .merge(&mut |line: &str| {
                // A throwing callback only loses a progress line.
                let _ = progress.call1(&JsValue::NULL, &JsValue::from_str(line));
            })
            .map_err(err)?;
        to_json(&report)
    }

    /// Aligns maps `a` and `b` again from a person's rough overlay: map
    /// `b`'s frame at `(x, y, theta)` (metres, radians) in map `a`'s frame.
    /// Returns the pair's result as JSON, in the report's `pairs[]` format
    /// (see `SavedMaps::refine`).
    pub fn refine(
        &mut self,
        a: u32,
        b: u32,
        x: f64,
        y: f64,
        theta: f64,
    ) -> Result<String, JsError> {
        let pair = self
            .inner
            .refine(a as usize, b as usize, Pose2::new(x, y, theta))
            .map_err(err)?;
        to_json(&pair)
    }

    /// Keeps a person's placement of maps `a` and `b` (map `b`'s frame at
    /// `(x, y, theta)` in map `a`'s) as it is, not verified; returns the
    /// pair's result as JSON (see `SavedMaps::keep_placement`).
    #[wasm_bindgen(js_name = keepPlacement)]
    pub fn keep_placement(
        &mut self,
        a: u32,
        b: u32,
        x: f64,
        y: f64,
        theta: f64,
    ) -> Result<String, JsError> {
        let pair = self
            .inner
            .keep_placement(a as usize, b as usize, Pose2::new(x, y, theta))
            .map_err(err)?;
        to_json(&pair)
    }

    /// The report's `maps` and `merge` as JSON, as `merge` returned it,
    /// after any `refine`.
    #[wasm_bindgen(js_name = reportJson)]
    pub fn report_json(&self) -> Result<String, JsError> {
        to_json(&self.inner.report().map_err(err)?)
    }

    /// The merged map (the maps joined to the first) as a binary PGM.
    #[wasm_bindgen(js_name = mergedPgm)]
    pub fn merged_pgm(&mut self) -> Result<Vec<u8>, JsError> {
        self.inner.merged_pgm().map_err(err)
    }

    /// The same pixels as a PNG.
    #[wasm_bindgen(js_name = mergedPng)]
    pub fn merged_png(&mut self) -> Result<Vec<u8>, JsError> {
        self.inner.merged_png().map_err(err)
    }

    /// The map_server YAML naming `image`.
    #[wasm_bindgen(js_name = mergedYaml)]
    pub fn merged_yaml(&mut self, image: &str) -> Result<String, JsError> {
        self.inner.merged_yaml(image).map_err(err)
    }

    /// Group `group`'s merged map (its maps joined in the frame of its
    /// first map; the report's `merge.groups[group]`) as a binary PGM.
    #[wasm_bindgen(js_name = groupPgm)]
    pub fn group_pgm(&mut self, group: u32) -> Result<Vec<u8>, JsError> {
        self.inner.group_pgm(group as usize).map_err(err)
    }

    /// The same pixels as a PNG.
    #[wasm_bindgen(js_name = groupPng)]
    pub fn group_png(&mut self, group: u32) -> Result<Vec<u8>, JsError> {
        self.inner.group_png(group as usize).map_err(err)
    }

    /// Group `group`'s map_server YAML naming `image`.
    #[wasm_bindgen(js_name = groupYaml)]
    pub fn group_yaml(&mut self, group: u32, image: &str) -> Result<String, JsError> {
        self.inner.group_yaml(group as usize, image).map_err(err)
    }
}

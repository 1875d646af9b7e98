//! # JavaScript boundary of map merging
//!
//! A third `#[wasm_bindgen] impl Lab` block. The page starts a merge, then
//! calls `mergeAdvance` from its animation loop with a small budget so the
//! matched-pair table fills in while the page stays responsive; each call
//! returns the progress as JSON, and `mergeViewJson` the tables and, at the
//! end, the verdict. Robot pairs and frame pairs are addressed by the
//! positions `mergeViewJson` lists.

use super::convert::{js_err as err, put_rgba, to_json as json};
use super::Lab;
use crate::lab::MergeMethod;
use wasm_bindgen::prelude::*;

#[wasm_bindgen]
impl Lab {
    /// Starts merging the run's maps with `method` (`auto`, `thesis` or
    /// `map-only`); returns the progress JSON. Throws before any run.
    #[wasm_bindgen(js_name = mergeStart)]
    pub fn merge_start(&mut self, method: &str) -> Result<String, JsError> {
        let method = MergeMethod::parse(method).map_err(err)?;
        json(&self.inner.merge_start(method).map_err(err)?)
    }

    /// The frames a merge with `method` would describe now that no other
    /// thread has described yet, flat: `[robot, frame, robot, frame, …]`
    /// (see `describeFrameSpec`). Empty before a run.
    #[wasm_bindgen(js_name = framesToDescribe)]
    pub fn frames_to_describe(&self, method: &str) -> Result<Vec<u32>, JsError> {
        let method = MergeMethod::parse(method).map_err(err)?;
        Ok(self
            .inner
            .frames_to_describe(method)
            .into_iter()
            .flat_map(|(r, i)| [r as u32, i as u32])
            .collect())
    }

    /// Whether robot `robot` of this run holds frame `index` now (the frame
    /// store thins its frames when full: a frame listed by
    /// `framesToDescribe` may be gone a few steps later).
    #[wasm_bindgen(js_name = hasFrame)]
    pub fn has_frame(&self, robot: u32, index: u32) -> bool {
        self.inner.has_frame(robot as usize, index as usize)
    }

    /// Frame `index` of robot `robot` of this run as JSON, for a lab of the
    /// same scenario in another thread to describe (`describeFrameSpec`).
    #[wasm_bindgen(js_name = frameSpecJson)]
    pub fn frame_spec_json(&self, robot: u32, index: u32) -> Result<String, JsError> {
        json(
            &self
                .inner
                .frame_spec(robot as usize, index as usize)
                .map_err(err)?,
        )
    }

    /// In a lab of the same scenario (a worker's): the SURF features of
    /// the frame `spec_json` (from `frameSpecJson`) as a merge with `method`
    /// describes them, packed as `[count, then 70 numbers per keypoint]`.
    #[wasm_bindgen(js_name = describeFrameSpec)]
    pub fn describe_frame_spec(
        &mut self,
        spec_json: &str,
        method: &str,
    ) -> Result<Vec<f32>, JsError> {
        let method = MergeMethod::parse(method).map_err(err)?;
        let spec: crate::lab::frame_spec::FrameSpec =
            serde_json::from_str(spec_json).map_err(|e| err(format!("frame spec: {e}")))?;
        self.inner
            .describe_frame_spec_packed(&spec, method)
            .map_err(err)
    }

    /// In a lab of the same scenario (a worker's): the grey pixels of the
    /// frame `spec_json` (from `frameSpecJson`), row by row, for this run's
    /// lab to describe with `describeRendered`.
    #[wasm_bindgen(js_name = renderFrameSpec)]
    pub fn render_frame_spec(&mut self, spec_json: &str) -> Result<Vec<u8>, JsError> {
        let spec: crate::lab::frame_spec::FrameSpec =
            serde_json::from_str(spec_json).map_err(|e| err(format!("frame spec: {e}")))?;
        Ok(self.inner.render_frame_spec(&spec).map_err(err)?.gray)
    }

    /// Describes frame `index` of robot `robot` of this run from its grey
    /// pixels (from `renderFrameSpec` in another lab of the same scenario)
    /// and keeps the features for the next merge with `method`. Returns
    /// false, keeping nothing, if the frame store thinned the frame since.
    #[wasm_bindgen(js_name = describeRendered)]
    pub fn describe_rendered(
        &mut self,
        robot: u32,
        index: u32,
        method: &str,
        gray: Vec<u8>,
    ) -> Result<bool, JsError> {
        let method = MergeMethod::parse(method).map_err(err)?;
        self.inner
            .describe_rendered(robot as usize, index as usize, method, gray)
            .map_err(err)
    }

    /// Keeps the packed features (from `describeFrameSpec`) of frame `index`
    /// of robot `robot` of this run for the next merge with `method`, which
    /// takes them instead of describing the frame itself. Returns false,
    /// keeping nothing, if the frame store thinned the frame since.
    #[wasm_bindgen(js_name = storeDescribed)]
    pub fn store_described(
        &mut self,
        robot: u32,
        index: u32,
        method: &str,
        packed: &[f32],
    ) -> Result<bool, JsError> {
        let method = MergeMethod::parse(method).map_err(err)?;
        self.inner
            .store_described_packed(robot as usize, index as usize, method, packed)
            .map_err(err)
    }

    /// Whether a merge of the current run exists (started, running or
    /// done); stepping, resetting or editing drops it.
    #[wasm_bindgen(js_name = hasMerge)]
    pub fn has_merge(&self) -> bool {
        self.inner.has_merge()
    }

    /// Does up to `units` units of work (frames described, frame pairs
    /// checked) in the current stage; returns the progress JSON
    /// `{stage, done, total, finished}`.
    #[wasm_bindgen(js_name = mergeAdvance)]
    pub fn merge_advance(&mut self, units: u32) -> Result<String, JsError> {
        json(&self.inner.merge_advance(units as usize).map_err(err)?)
    }

    /// Runs the merge to its end; returns the progress JSON.
    #[wasm_bindgen(js_name = mergeFinish)]
    pub fn merge_finish(&mut self) -> Result<String, JsError> {
        json(&self.inner.merge_finish().map_err(err)?)
    }

    /// Progress, the selected frames, the tables so far and (when done) the
    /// verdict with its errors, as JSON.
    #[wasm_bindgen(js_name = mergeViewJson)]
    pub fn merge_view_json(&self) -> Result<String, JsError> {
        json(&self.inner.merge_view().map_err(err)?)
    }

    /// The current merge's image selection (thesis §6.2.2) with the numbers
    /// behind it, as JSON: `{method, sonar_tolerance_m, min_front_range_m,
    /// max_front_range_m, max_turn_per_step_rad, min_separation_m, robots:
    /// [{name, captured, square, selected: [{frame, step, sonar4_m,
    /// sonar5_m, pose}]}]}`. `square` counts the captured frames that pass
    /// the squareness test (sonars 4 and 5 alike, not turning) before the
    /// thinning; `selected` lists the frames that take part, in table
    /// order, with the robot's own SLAM pose `[x, y, theta]` at capture
    /// (its map frame, never the truth).
    #[wasm_bindgen(js_name = mergeSelectionJson)]
    pub fn merge_selection_json(&self) -> Result<String, JsError> {
        json(&self.inner.merge_selection().map_err(err)?)
    }

    /// One checked frame pair's matches, homography, quad and candidate
    /// transform (JSON); `pair`, `row` and `col` as in `mergeViewJson`.
    #[wasm_bindgen(js_name = mergePairJson)]
    pub fn merge_pair_json(&self, pair: u32, row: u32, col: u32) -> Result<String, JsError> {
        json(
            &self
                .inner
                .merge_pair_view(pair as usize, row as usize, col as usize)
                .map_err(err)?,
        )
    }

    /// Draws the merged map, fitted, with the robots' paths, into a canvas
    /// context of `width × height`.
    #[wasm_bindgen(js_name = drawMerged)]
    pub fn draw_merged(
        &self,
        ctx: &web_sys::CanvasRenderingContext2d,
        width: u32,
        height: u32,
    ) -> Result<(), JsError> {
        let rgba = self.inner.merged_rgba(width, height).map_err(err)?;
        put_rgba(ctx, &rgba, width, height)
    }

    /// The merged map as straight RGBA pixels (for node and tests).
    #[wasm_bindgen(js_name = mergedRgba)]
    pub fn merged_rgba(&self, width: u32, height: u32) -> Result<Vec<u8>, JsError> {
        self.inner.merged_rgba(width, height).map_err(err)
    }

    /// The merged map as ROS map_server files: binary PGM ...
    #[wasm_bindgen(js_name = mergedPgm)]
    pub fn merged_pgm(&self) -> Result<Vec<u8>, JsError> {
        self.inner.merged_pgm().map_err(err)
    }

    /// ... the YAML naming `image` ...
    #[wasm_bindgen(js_name = mergedYaml)]
    pub fn merged_yaml(&self, image: &str) -> Result<String, JsError> {
        self.inner.merged_yaml(image).map_err(err)
    }

    /// ... and a PNG of the same pixels.
    #[wasm_bindgen(js_name = mergedPng)]
    pub fn merged_png(&self) -> Result<Vec<u8>, JsError> {
        self.inner.merged_png().map_err(err)
    }

    /// Every group of robots the finished merge joined, as JSON: `[{group,
    /// robots, transforms, reason (groups of one), errors}]`, each group in
    /// the frame of its first robot, robot 1's group first, with each
    /// member's error against the ground truth (`crate::lab::groups`).
    #[wasm_bindgen(js_name = mergeGroupsJson)]
    pub fn merge_groups_json(&self) -> Result<String, JsError> {
        json(&self.inner.merge_groups().map_err(err)?)
    }

    /// Draws group `group`'s merged map, fitted, with its robots' paths,
    /// into a canvas context of `width × height`.
    #[wasm_bindgen(js_name = drawGroupMerged)]
    pub fn draw_group_merged(
        &self,
        ctx: &web_sys::CanvasRenderingContext2d,
        group: u32,
        width: u32,
        height: u32,
    ) -> Result<(), JsError> {
        let rgba = self
            .inner
            .group_merged_rgba(group as usize, width, height)
            .map_err(err)?;
        put_rgba(ctx, &rgba, width, height)
    }

    /// Group `group`'s merged map as straight RGBA pixels (for node and tests).
    #[wasm_bindgen(js_name = groupMergedRgba)]
    pub fn group_merged_rgba(
        &self,
        group: u32,
        width: u32,
        height: u32,
    ) -> Result<Vec<u8>, JsError> {
        self.inner
            .group_merged_rgba(group as usize, width, height)
            .map_err(err)
    }

    /// Group `group`'s merged map as ROS map_server files: binary PGM ...
    #[wasm_bindgen(js_name = groupMergedPgm)]
    pub fn group_merged_pgm(&self, group: u32) -> Result<Vec<u8>, JsError> {
        self.inner.group_merged_pgm(group as usize).map_err(err)
    }

    /// ... the YAML naming `image` ...
    #[wasm_bindgen(js_name = groupMergedYaml)]
    pub fn group_merged_yaml(&self, group: u32, image: &str) -> Result<String, JsError> {
        self.inner
            .group_merged_yaml(group as usize, image)
            .map_err(err)
    }

    /// ... and a PNG of the same pixels.
    #[wasm_bindgen(js_name = groupMergedPng)]
    pub fn group_merged_png(&self, group: u32) -> Result<Vec<u8>, JsError> {
        self.inner.group_merged_png(group as usize).map_err(err)
    }
}

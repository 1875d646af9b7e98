//! # The small views the page and the command line read
//!
//! JSON objects a caller reads beside the big ones (the report, the merge
//! view): placement problems, the fitted view, the grid and scale-bar
//! spacing, the camera's size, a captured frame's metadata, and the merge's
//! image selection with the numbers behind it. They are built here, in the
//! session layer, so [`crate::bindings`] only passes them through. Their
//! keys are fixed (the page and `web/cli.mjs` read them); `serde_json`
//! writes an object's keys in sorted order.

use super::Lab;
use crate::camera::capture::CapturedFrame;
use crate::merge::selection::{is_square, SONAR_4, SONAR_5};
use crate::render::{grid_step_m, scale_bar_m};
use serde_json::{json, Value};

/// A captured frame's metadata: `{index, step, time_s, odometry: [x, y,
/// theta], truth: [x, y, theta]}` (no pixels).
pub fn frame_meta(f: &CapturedFrame) -> Value {
    json!({
        "index": f.index,
        "step": f.step,
        "time_s": f.time_s,
        "odometry": [f.odometry.x, f.odometry.y, f.odometry.theta],
        "truth": [f.truth.x, f.truth.y, f.truth.theta],
    })
}

impl Lab {
    /// Placement problems, as a JSON array of `{field, message, text}`.
    pub fn problems_json(&self) -> String {
        let v: Vec<Value> = self
            .problems()
            .iter()
            .map(|p| json!({"field": p.field, "message": p.message, "text": p.to_string()}))
            .collect();
        Value::Array(v).to_string()
    }

    /// Fits the view to the scenario for a canvas of the given size; the
    /// new `{center, scale}` as JSON.
    pub fn fit_view_json(&mut self, width: u32, height: u32) -> Result<String, String> {
        let v = self.fit_view(width, height)?;
        Ok(json!({"center": v.center, "scale": v.scale}).to_string())
    }

    /// Grid spacing and scale-bar length (m) at the current zoom, as JSON
    /// `{grid_m, scale_bar_m}`.
    pub fn view_metrics_json(&self) -> String {
        let s = self.view().scale;
        json!({"grid_m": grid_step_m(s), "scale_bar_m": scale_bar_m(s)}).to_string()
    }

    /// The camera image size, field of view and capture period as JSON
    /// `{width, height, hfov_deg, period_s}`.
    pub fn camera_info_json(&self) -> String {
        let c = &self.scenario().camera;
        json!({"width": c.width, "height": c.height, "hfov_deg": c.hfov_deg, "period_s": c.period_s}).to_string()
    }

    /// Robot `robot`'s captured frames' metadata ([`frame_meta`]) as a JSON
    /// array.
    pub fn frames_json(&self, robot: usize) -> Result<String, String> {
        let v: Vec<Value> = self.frames(robot)?.iter().map(frame_meta).collect();
        Ok(Value::Array(v).to_string())
    }

    /// Metadata of frame `index` of robot `robot` ([`frame_meta`]) as JSON.
    pub fn frame_json(&self, robot: usize, index: usize) -> Result<String, String> {
        Ok(frame_meta(self.frame(robot, index)?).to_string())
    }

    /// The current merge's image selection (thesis §6.2.2) with the numbers
    /// behind it: `{method, sonar_tolerance_m, min_front_range_m,
    /// max_front_range_m, max_turn_per_step_rad, min_separation_m,
    /// min_motion_m, min_turn_rad, robots: [{name, captured, square,
    /// selected: [{frame, step, sonar4_m, sonar5_m, pose}]}]}`. The thesis
    /// method keeps square frames `min_separation_m` apart; the automatic
    /// method keeps a frame unless one already kept was taken within
    /// `min_motion_m` and `min_turn_rad` of it. `square` counts the captured frames that pass
    /// the squareness test (sonars 4 and 5 alike, not turning) before the
    /// thinning; `selected` lists the frames that take part, in table
    /// order, with the robot's own SLAM pose `[x, y, theta]` at capture
    /// (its map frame, never the truth).
    pub fn merge_selection(&self) -> Result<Value, String> {
        let job = self.merge.as_ref().ok_or("no merge has been started")?;
        let cfg = &job.config.selection;
        let mm = |x: f64| (x * 1000.0).round() / 1000.0;
        let robots: Vec<Value> = job
            .robots
            .iter()
            .map(|r| {
                let selected: Vec<Value> = r
                    .selected
                    .iter()
                    .map(|&k| {
                        let f = &r.infos[k];
                        json!({
                            "frame": f.index,
                            "step": f.step,
                            "sonar4_m": mm(f64::from(f.sonar_m[SONAR_4])),
                            "sonar5_m": mm(f64::from(f.sonar_m[SONAR_5])),
                            "pose": [f.pose.x, f.pose.y, f.pose.theta],
                        })
                    })
                    .collect();
                json!({
                    "name": r.name,
                    "captured": r.infos.len(),
                    "square": r.infos.iter().filter(|f| is_square(f, cfg)).count(),
                    "selected": selected,
                })
            })
            .collect();
        Ok(json!({
            "method": job.config.method.name(),
            "sonar_tolerance_m": cfg.sonar_tolerance_m,
            "min_front_range_m": cfg.min_front_range_m,
            "max_front_range_m": cfg.max_front_range_m,
            "max_turn_per_step_rad": cfg.max_turn_per_step_rad,
            "min_separation_m": cfg.min_separation_m,
            "min_motion_m": job.config.min_motion_m,
            "min_turn_rad": job.config.min_turn_rad,
            "robots": robots,
        }))
    }

    /// Whether a merge of the current run exists (started, running or
    /// done); stepping, resetting or editing drops it.
    pub fn has_merge(&self) -> bool {
        self.merge.is_some()
    }
}

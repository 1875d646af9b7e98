//! # The JavaScript boundary
//!
//! The only module that knows about wasm-bindgen. It wraps the pure-Rust
//! [`crate::lab::Lab`] in a `#[wasm_bindgen]` struct and converts at the
//! edge: data crosses as numbers, strings of JSON, and byte arrays; every
//! function returns `Result<_, JsError>` so bad input reaches JavaScript as
//! an exception with a message, never as a panic or a trap.

pub mod surf;

use crate::lab;
use crate::render::{grid_step_m, scale_bar_m, RenderOptions};
use crate::report::Timings;
use crate::scenario::Scenario;
use wasm_bindgen::prelude::*;
use wasm_bindgen::Clamped;

fn js_err(e: impl std::fmt::Display) -> JsError {
    JsError::new(&e.to_string())
}

/// Installs a panic hook that prints Rust panics to the console (a panic
/// would be a bug: every input error is a `JsError`).
#[wasm_bindgen(start)]
pub fn start() {
    console_error_panic_hook::set_once();
}

/// Checks a scenario fully (shape and placement) and returns it with every
/// default filled in, as pretty JSON.
#[wasm_bindgen(js_name = validateScenario)]
pub fn validate_scenario(json: &str) -> Result<String, JsError> {
    let s = Scenario::from_json(json).map_err(js_err)?;
    Ok(s.to_json_pretty())
}

/// The crate version, for the page's footer and reports.
#[wasm_bindgen]
pub fn version() -> String {
    env!("CARGO_PKG_VERSION").to_string()
}

/// The robot colours the renderer uses, by robot index, as JSON
/// `[[r, g, b], ...]` (the page's legend and readouts use the same).
#[wasm_bindgen(js_name = robotColours)]
pub fn robot_colours() -> String {
    serde_json::to_string(&crate::render::ROBOT_COLOURS).unwrap_or_else(|_| "[]".into())
}

/// Whether this build was compiled with wasm SIMD128.
#[wasm_bindgen(js_name = simdEnabled)]
pub fn simd_enabled() -> bool {
    cfg!(target_feature = "simd128")
}

/// A lab session: the scenario being edited and, once started, its run.
#[wasm_bindgen]
pub struct Lab {
    inner: lab::Lab,
}

#[wasm_bindgen]
impl Lab {
    /// A session on a scenario (JSON text). Throws if it cannot be parsed;
    /// robots placed inside walls are accepted while editing (see
    /// `problems()`), but such a scenario will not run.
    #[wasm_bindgen(constructor)]
    pub fn new(scenario_json: &str) -> Result<Lab, JsError> {
        Ok(Lab {
            inner: lab::Lab::new(scenario_json).map_err(js_err)?,
        })
    }

    /// Replaces the scenario and stops the run. On error nothing changes.
    #[wasm_bindgen(js_name = setScenario)]
    pub fn set_scenario(&mut self, scenario_json: &str) -> Result<(), JsError> {
        self.inner.set_scenario(scenario_json).map_err(js_err)
    }

    /// The current scenario with defaults filled in (pretty JSON).
    #[wasm_bindgen(js_name = scenarioJson)]
    pub fn scenario_json(&self) -> String {
        self.inner.scenario().to_json_pretty()
    }

    /// Placement problems, as a JSON array of `{field, message}`.
    #[wasm_bindgen(js_name = problemsJson)]
    pub fn problems_json(&self) -> String {
        let v: Vec<serde_json::Value> = self
            .inner
            .problems()
            .iter()
            .map(|p| serde_json::json!({"field": p.field, "message": p.message, "text": p.to_string()}))
            .collect();
        serde_json::Value::Array(v).to_string()
    }

    /// Sets the seed (a whole number from 0 to 2^53) and stops the run.
    #[wasm_bindgen(js_name = setSeed)]
    pub fn set_seed(&mut self, seed: f64) -> Result<(), JsError> {
        if !(seed.is_finite()
            && seed >= 0.0
            && seed.fract() == 0.0
            && seed <= 9_007_199_254_740_992.0)
        {
            return Err(JsError::new(&format!(
                "seed: {seed} is not a whole number from 0 to 2^53"
            )));
        }
        self.inner.set_seed(seed as u64);
        Ok(())
    }

    /// Sets the run's duration in simulated seconds.
    #[wasm_bindgen(js_name = setDuration)]
    pub fn set_duration(&mut self, duration_s: f64) -> Result<(), JsError> {
        self.inner.set_duration(duration_s).map_err(js_err)
    }

    /// Back to time 0.
    pub fn reset(&mut self) {
        self.inner.reset();
    }

    /// Advances up to `n` control steps (0.1 s each); returns the number
    /// taken. Throws, naming the field, if the scenario cannot run.
    pub fn step(&mut self, n: u32) -> Result<u32, JsError> {
        Ok(self.inner.step(n as usize).map_err(js_err)? as u32)
    }

    /// Runs to the end of the scenario's duration.
    #[wasm_bindgen(js_name = runToEnd)]
    pub fn run_to_end(&mut self) -> Result<(), JsError> {
        self.inner.run_to_end().map_err(js_err)
    }

    /// Simulated time (s).
    #[wasm_bindgen(js_name = timeS)]
    pub fn time_s(&self) -> f64 {
        self.inner.state().time_s
    }

    /// Live state for readouts (JSON).
    #[wasm_bindgen(js_name = stateJson)]
    pub fn state_json(&self) -> Result<String, JsError> {
        serde_json::to_string(&self.inner.state()).map_err(js_err)
    }

    /// Sets the view (JSON: width, height, center, scale, layers,
    /// selected_wall, selected_robot, preview_wall).
    #[wasm_bindgen(js_name = setView)]
    pub fn set_view(&mut self, view_json: &str) -> Result<(), JsError> {
        let v: RenderOptions =
            serde_json::from_str(view_json).map_err(|e| js_err(format!("view: {e}")))?;
        self.inner.set_view(v).map_err(js_err)
    }

    /// Fits the view to the scenario for a canvas of the given size; returns
    /// `{center, scale}` as JSON.
    #[wasm_bindgen(js_name = fitView)]
    pub fn fit_view(&mut self, width: u32, height: u32) -> Result<String, JsError> {
        let v = self.inner.fit_view(width, height).map_err(js_err)?;
        Ok(serde_json::json!({"center": v.center, "scale": v.scale}).to_string())
    }

    /// Grid spacing and scale-bar length (m) the renderer uses at a zoom,
    /// so the page can label them.
    #[wasm_bindgen(js_name = viewMetrics)]
    pub fn view_metrics(&self) -> String {
        let s = self.inner.view().scale;
        serde_json::json!({"grid_m": grid_step_m(s), "scale_bar_m": scale_bar_m(s)}).to_string()
    }

    /// Renders the view and draws it into a 2-D canvas context.
    pub fn draw(&mut self, ctx: &web_sys::CanvasRenderingContext2d) -> Result<(), JsError> {
        let pm = self.inner.render().map_err(js_err)?;
        let img = web_sys::ImageData::new_with_u8_clamped_array_and_sh(
            Clamped(pm.data()),
            pm.width(),
            pm.height(),
        )
        .map_err(|_| JsError::new("could not make ImageData"))?;
        ctx.put_image_data(&img, 0.0, 0.0)
            .map_err(|_| JsError::new("could not draw into the canvas"))
    }

    /// Renders the view into the lab's own image without copying it out
    /// (for benchmarks; `draw` and `renderRgba` render too).
    #[wasm_bindgen(js_name = renderFrame)]
    pub fn render_frame(&mut self) -> Result<(), JsError> {
        self.inner.render().map(|_| ()).map_err(js_err)
    }

    /// Renders the view and returns its RGBA pixels (width*height*4 bytes).
    #[wasm_bindgen(js_name = renderRgba)]
    pub fn render_rgba(&mut self) -> Result<Vec<u8>, JsError> {
        Ok(self.inner.render().map_err(js_err)?.data().to_vec())
    }

    /// The run report (JSON); `timings_json` carries wall-clock timings
    /// measured by the caller, e.g. `{"simulate": 12.5, "total": 20.1}`.
    #[wasm_bindgen(js_name = reportJson)]
    pub fn report_json(&self, timings_json: &str) -> Result<String, JsError> {
        let t: Timings =
            serde_json::from_str(timings_json).map_err(|e| js_err(format!("timings: {e}")))?;
        Ok(self.inner.report(t).map_err(js_err)?.to_json())
    }

    /// One robot's log as CSV (the thesis's layout).
    #[wasm_bindgen(js_name = logCsv)]
    pub fn log_csv(&self, robot: u32) -> Result<String, JsError> {
        self.inner.log_csv(robot as usize).map_err(js_err)
    }
}

//! # The JavaScript boundary
//!
//! The only module that knows about wasm-bindgen. It wraps the pure-Rust
//! [`crate::lab::Lab`] in a `#[wasm_bindgen]` struct and converts at the
//! edge: data crosses as numbers, strings of JSON, and byte arrays; every
//! function returns `Result<_, JsError>` so bad input reaches JavaScript as
//! an exception with a message, never as a panic or a trap.

mod bags;
mod logs;
mod maps;
mod merge;
mod slam;
mod surf;

/// The one error conversion, JSON serialisation and pixel copy every
/// binding block uses.
mod convert;

use crate::lab;
use crate::lab::report::Timings;
use crate::lab::RenderOptions;
use convert::{js_err, put_rgba, ChunkSink};
use wasm_bindgen::prelude::*;

#[wasm_bindgen]
extern "C" {
    #[wasm_bindgen(js_namespace = performance, js_name = now)]
    fn performance_now() -> f64;
}

thread_local! {
    /// Whether the host has `performance.now()`, looked up once: the
    /// simulation reads the clock a few times per step, and a property
    /// lookup by name each time cost 2 % of a whole run.
    static HAS_PERFORMANCE: bool = js_sys::Reflect::get(&js_sys::global(), &JsValue::from_str("performance"))
        .ok()
        .filter(|p| p.is_object())
        .and_then(|p| js_sys::Reflect::get(&p, &JsValue::from_str("now")).ok())
        .is_some_and(|now| now.is_function());
}

/// `performance.now()` where the host has it (browsers, node), else
/// `Date.now()`: the clock the lab times its stages with.
fn now_ms() -> f64 {
    if HAS_PERFORMANCE.with(|h| *h) {
        performance_now()
    } else {
        js_sys::Date::now()
    }
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
    lab::validate_scenario(json).map_err(js_err)
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
    lab::robot_colours_json()
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
        let mut inner = lab::Lab::new(scenario_json).map_err(js_err)?;
        inner.set_clock(now_ms);
        Ok(Lab { inner })
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
        self.inner.problems_json()
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

    /// Sets the bytes of camera frames all robots may keep together (the
    /// frame store thins beyond it; default 16 MiB) and stops the run.
    #[wasm_bindgen(js_name = setFrameBudget)]
    pub fn set_frame_budget(&mut self, bytes: f64) -> Result<(), JsError> {
        if !(bytes.is_finite() && bytes >= 0.0 && bytes.fract() == 0.0 && bytes <= 4.0e9) {
            return Err(JsError::new(&format!(
                "frame budget: {bytes} is not a whole number of bytes from 0 to 4e9"
            )));
        }
        self.inner.set_frame_budget(bytes as usize);
        Ok(())
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
        convert::to_json(&self.inner.state())
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
        self.inner.fit_view_json(width, height).map_err(js_err)
    }

    /// Grid spacing and scale-bar length (m) the renderer uses at a zoom,
    /// so the page can label them.
    #[wasm_bindgen(js_name = viewMetrics)]
    pub fn view_metrics(&self) -> String {
        self.inner.view_metrics_json()
    }

    /// Renders the view and draws it into a 2-D canvas context.
    pub fn draw(&mut self, ctx: &web_sys::CanvasRenderingContext2d) -> Result<(), JsError> {
        let pm = self.inner.render().map_err(js_err)?;
        put_rgba(ctx, pm.data(), pm.width(), pm.height())
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

    /// The same report, byte for byte, handed to `write` in chunks (each a
    /// `Uint8Array` of UTF-8) as it is made: what `run --json` prints, without
    /// ever holding the whole text (75 MB for sixteen robots over an hour).
    /// An exception thrown by `write` ends the writing and is rethrown with
    /// its message.
    #[wasm_bindgen(js_name = writeReport)]
    pub fn write_report(
        &self,
        timings_json: &str,
        write: &js_sys::Function,
    ) -> Result<(), JsError> {
        let t: Timings =
            serde_json::from_str(timings_json).map_err(|e| js_err(format!("timings: {e}")))?;
        let report = self.inner.report(t).map_err(js_err)?;
        let mut sink = ChunkSink::new(write);
        let written = report
            .write_json(&mut sink)
            .and_then(|()| std::io::Write::flush(&mut sink).map_err(|e| e.to_string()));
        match (written, sink.thrown.take()) {
            (_, Some(thrown)) => Err(js_err(format!(
                "writing the report: {}",
                convert::message_of(&thrown)
            ))),
            (Err(e), None) => Err(js_err(e)),
            (Ok(()), None) => Ok(()),
        }
    }

    /// The camera image size as JSON `{width, height, hfov_deg}`.
    #[wasm_bindgen(js_name = cameraInfo)]
    pub fn camera_info(&self) -> String {
        self.inner.camera_info_json()
    }

    /// Draws what robot `robot`'s camera sees now (noise-free, in colour) into
    /// a canvas context at the camera's resolution.
    #[wasm_bindgen(js_name = drawCamera)]
    pub fn draw_camera(
        &mut self,
        robot: u32,
        ctx: &web_sys::CanvasRenderingContext2d,
    ) -> Result<(), JsError> {
        let img = self
            .inner
            .camera_view(robot as usize, true)
            .map_err(js_err)?;
        let rgba = img.rgba.ok_or_else(|| JsError::new("no colour image"))?;
        put_rgba(ctx, &rgba, img.width, img.height)
    }

    /// The camera view of robot `robot` as grey bytes (width*height).
    #[wasm_bindgen(js_name = cameraGray)]
    pub fn camera_gray(&mut self, robot: u32) -> Result<Vec<u8>, JsError> {
        Ok(self
            .inner
            .camera_view(robot as usize, false)
            .map_err(js_err)?
            .gray)
    }

    /// Robot `robot`'s captured frames as JSON: `[{index, step, time_s,
    /// odometry: [x, y, theta], truth: [x, y, theta]}]` (no pixels).
    #[wasm_bindgen(js_name = framesJson)]
    pub fn frames_json(&self, robot: u32) -> Result<String, JsError> {
        self.inner.frames_json(robot as usize).map_err(js_err)
    }

    /// How many frames robot `robot` has captured (and kept).
    #[wasm_bindgen(js_name = frameCount)]
    pub fn frame_count(&self, robot: u32) -> Result<u32, JsError> {
        Ok(self.inner.frames(robot as usize).map_err(js_err)?.len() as u32)
    }

    /// Metadata of frame `index` of robot `robot`, as JSON.
    #[wasm_bindgen(js_name = frameJson)]
    pub fn frame_json(&self, robot: u32, index: u32) -> Result<String, JsError> {
        self.inner
            .frame_json(robot as usize, index as usize)
            .map_err(js_err)
    }

    /// Draws captured frame `index` of robot `robot` (grey) into a context.
    #[wasm_bindgen(js_name = drawFrame)]
    pub fn draw_frame(
        &self,
        robot: u32,
        index: u32,
        ctx: &web_sys::CanvasRenderingContext2d,
    ) -> Result<(), JsError> {
        let img = self
            .inner
            .frame_grey(robot as usize, index as usize)
            .map_err(js_err)?;
        let rgba: Vec<u8> = img.gray.iter().flat_map(|&g| [g, g, g, 255]).collect();
        put_rgba(ctx, &rgba, img.width, img.height)
    }

    /// Draws captured frame `index` of robot `robot` as a thumbnail `width`
    /// pixels wide (1 … the camera's width; the height in proportion): the
    /// frame's pose rendered by a smaller camera with the same field of view
    /// ([`crate::camera::PinholeCamera::scaled`]), grey, without the pixel
    /// noise. The film strip's thumbnails, at a fraction of a frame's cost.
    #[wasm_bindgen(js_name = drawFrameThumb)]
    pub fn draw_frame_thumb(
        &self,
        robot: u32,
        index: u32,
        width: u32,
        ctx: &web_sys::CanvasRenderingContext2d,
    ) -> Result<(), JsError> {
        let img = self
            .inner
            .frame_thumbnail(robot as usize, index as usize, width)
            .map_err(js_err)?;
        let rgba: Vec<u8> = img.gray.iter().flat_map(|&g| [g, g, g, 255]).collect();
        put_rgba(ctx, &rgba, img.width, img.height)
    }

    /// Captured frame `index` of robot `robot` as grey bytes.
    #[wasm_bindgen(js_name = frameGray)]
    pub fn frame_gray(&self, robot: u32, index: u32) -> Result<Vec<u8>, JsError> {
        Ok(self
            .inner
            .frame_grey(robot as usize, index as usize)
            .map_err(js_err)?
            .gray)
    }

    /// Captured frame `index` of robot `robot` as a PNG file (8-bit grey).
    #[wasm_bindgen(js_name = framePng)]
    pub fn frame_png(&self, robot: u32, index: u32) -> Result<Vec<u8>, JsError> {
        self.inner
            .frame_png(robot as usize, index as usize)
            .map_err(js_err)
    }

    /// Puts a PNG or JPEG picture on every wall whose texture is `image:NAME`.
    #[wasm_bindgen(js_name = addImageTexture)]
    pub fn add_image_texture(&mut self, name: &str, bytes: &[u8]) -> Result<(), JsError> {
        self.inner.add_image_texture(name, bytes).map_err(js_err)
    }

    /// One robot's log as CSV (the thesis's layout).
    #[wasm_bindgen(js_name = logCsv)]
    pub fn log_csv(&self, robot: u32) -> Result<String, JsError> {
        self.inner.log_csv(robot as usize).map_err(js_err)
    }
}

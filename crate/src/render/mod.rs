//! # Drawing the world with tiny-skia
//!
//! The page shows the world from above: a metric grid, the walls (tinted with
//! a hint of their texture's colour), each robot's body and heading, its laser
//! rays (with more than [`RAY_ROBOTS`] robots, a fan for all but the selected
//! one) and sonar cones, and two trajectories per robot — the **true** path
//! (solid) and the path its **odometry** believes (dashed, drawn from the true
//! start pose so that drift shows as the two paths parting).
//!
//! Rendering is pure: a [`RenderOptions`] (view, layers, editing overlays)
//! plus the scenario and, when one is running, the simulation, into an RGBA
//! [`Pixmap`]. World coordinates have y up; this is the one place y is
//! flipped. The background is opaque, so tiny-skia's premultiplied pixels
//! equal the straight RGBA a canvas `ImageData` expects.
//!
//! The page redraws its view many times a second, so what changes rarely
//! is kept drawn on layers between redraws ([`ViewLayers`]): the walls
//! ([`WallLayer`]) and the robots' paths ([`TrailLayer`], in `trails.rs`,
//! which strokes only what the robots added since the last redraw).

use crate::geom::Pose2;
use crate::kinematics::P2dx;
use crate::palette::{robot_colour, texture_hint};
use crate::scenario::Scenario;
use crate::sensors::laser::beam_bearing;
use crate::sensors::sonar::SONAR_COUNT;
use crate::sensors::Sonar;
use crate::sim::{RobotSim, Simulation};
use glam::DVec2;
use serde::Deserialize;
pub use trails::TrailLayer;

mod trails;
use tiny_skia::{
    Color, FillRule, LineCap, LineJoin, Paint, PathBuilder, Pixmap, Rect, Stroke, StrokeDash,
    Transform,
};

/// Which layers to draw.
#[derive(Clone, Debug, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Layers {
    pub grid: bool,
    pub laser: bool,
    pub sonar: bool,
    pub truth_path: bool,
    pub odometry_path: bool,
}

impl Default for Layers {
    fn default() -> Self {
        Layers {
            grid: true,
            laser: true,
            sonar: false,
            truth_path: true,
            odometry_path: true,
        }
    }
}

/// What to draw and where.
#[derive(Clone, Debug, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RenderOptions {
    pub width: u32,
    pub height: u32,
    /// World point at the centre of the image (m).
    pub center: [f64; 2],
    /// Zoom (pixels per metre).
    pub scale: f64,
    pub layers: Layers,
    /// A wall to highlight (selection in the editor).
    pub selected_wall: Option<usize>,
    /// A robot to highlight.
    pub selected_robot: Option<usize>,
    /// A wall being drawn: `[x0, y0, x1, y1]`.
    pub preview_wall: Option<[f64; 4]>,
    /// Where a camera frame was taken, `[x, y, theta]`: drawn as the
    /// camera's field of view.
    pub marker: Option<[f64; 3]>,
    /// The camera's horizontal field of view, for the marker (rad).
    pub marker_fov: f64,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            width: 960,
            height: 720,
            center: [10.0, 7.5],
            scale: 40.0,
            layers: Layers::default(),
            selected_wall: None,
            selected_robot: None,
            preview_wall: None,
            marker: None,
            marker_fov: 60f64.to_radians(),
        }
    }
}

impl RenderOptions {
    /// Checks sizes and numbers; returns a message naming the bad field.
    pub fn validate(&self) -> Result<(), String> {
        if self.width == 0 || self.height == 0 || self.width > 4096 || self.height > 4096 {
            return Err(format!(
                "view size {}x{} must be between 1x1 and 4096x4096",
                self.width, self.height
            ));
        }
        if !(self.scale.is_finite() && self.scale > 0.01 && self.scale < 10_000.0) {
            return Err(format!(
                "view scale {} must be in (0.01, 10000) px/m",
                self.scale
            ));
        }
        if !(self.center[0].is_finite() && self.center[1].is_finite()) {
            return Err("view center must be finite".into());
        }
        Ok(())
    }

    /// Fits the view to the scenario's extent with a margin.
    pub fn fit(&mut self, scenario: &Scenario) {
        let (lo, hi) = scenario.bounds();
        let size = (hi - lo).max(DVec2::splat(1.0)) + DVec2::splat(2.0);
        self.center = [(lo.x + hi.x) / 2.0, (lo.y + hi.y) / 2.0];
        self.scale = (self.width as f64 / size.x).min(self.height as f64 / size.y);
    }

    /// World point to pixel.
    pub fn to_px(&self, p: DVec2) -> (f32, f32) {
        (
            ((p.x - self.center[0]) * self.scale + self.width as f64 / 2.0) as f32,
            (self.height as f64 / 2.0 - (p.y - self.center[1]) * self.scale) as f32,
        )
    }
}

fn paint(rgb: [u8; 3], alpha: f32) -> Paint<'static> {
    let mut p = Paint::default();
    p.set_color(Color::from_rgba8(
        rgb[0],
        rgb[1],
        rgb[2],
        (alpha.clamp(0.0, 1.0) * 255.0) as u8,
    ));
    p.anti_alias = true;
    p
}

fn stroke(width: f32) -> Stroke {
    Stroke {
        width,
        line_cap: LineCap::Round,
        line_join: LineJoin::Round,
        ..Stroke::default()
    }
}

/// Draws a polyline of world points. Points closer than `min_step_px` to
/// the last one kept are dropped (a long trajectory looks the same with a
/// far shorter path); 0 keeps every point.
fn polyline(
    pm: &mut Pixmap,
    o: &RenderOptions,
    pts: impl Iterator<Item = DVec2>,
    min_step_px: f32,
    p: &Paint,
    s: &Stroke,
) {
    let min2 = min_step_px * min_step_px;
    let mut pb = PathBuilder::new();
    let mut last: Option<(f32, f32)> = None;
    let mut pending: Option<(f32, f32)> = None;
    for w in pts {
        let (x, y) = o.to_px(w);
        match last {
            None => {
                pb.move_to(x, y);
                last = Some((x, y));
            }
            Some((lx, ly)) if (x - lx).powi(2) + (y - ly).powi(2) >= min2 => {
                pb.line_to(x, y);
                last = Some((x, y));
                pending = None;
            }
            Some(_) => pending = Some((x, y)),
        }
    }
    if let Some((x, y)) = pending {
        pb.line_to(x, y);
    }
    if let Some(path) = pb.finish() {
        pm.stroke_path(&path, p, s, Transform::identity(), None);
    }
}

fn polygon(
    pm: &mut Pixmap,
    o: &RenderOptions,
    pts: &[DVec2],
    fill: Option<&Paint>,
    line: Option<(&Paint, &Stroke)>,
) {
    let mut pb = PathBuilder::new();
    for (i, &w) in pts.iter().enumerate() {
        let (x, y) = o.to_px(w);
        if i == 0 {
            pb.move_to(x, y);
        } else {
            pb.line_to(x, y);
        }
    }
    pb.close();
    if let Some(path) = pb.finish() {
        if let Some(f) = fill {
            pm.fill_path(&path, f, FillRule::Winding, Transform::identity(), None);
        }
        if let Some((p, s)) = line {
            pm.stroke_path(&path, p, s, Transform::identity(), None);
        }
    }
}

/// Strokes many world segments as one path (one rasterisation pass).
fn segments(pm: &mut Pixmap, o: &RenderOptions, segs: &[(DVec2, DVec2)], p: &Paint, s: &Stroke) {
    let mut pb = PathBuilder::new();
    for &(a, b) in segs {
        let (x0, y0) = o.to_px(a);
        let (x1, y1) = o.to_px(b);
        pb.move_to(x0, y0);
        pb.line_to(x1, y1);
    }
    if let Some(path) = pb.finish() {
        pm.stroke_path(&path, p, s, Transform::identity(), None);
    }
}

fn nice_step(target_m: f64) -> f64 {
    let mut step = 0.1;
    for s in [
        0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 200.0, 500.0,
    ] {
        step = s;
        if s >= target_m {
            break;
        }
    }
    step
}

/// Grid spacing (m) for a zoom: lines about 40 px apart or more.
pub fn grid_step_m(scale_px_per_m: f64) -> f64 {
    nice_step(40.0 / scale_px_per_m)
}

/// Scale-bar length (m) for a zoom: the longest round length that fits in
/// 120 px.
pub fn scale_bar_m(scale_px_per_m: f64) -> f64 {
    let mut best = 0.1;
    for s in [
        0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 200.0, 500.0,
    ] {
        if s * scale_px_per_m <= 120.0 {
            best = s;
        }
    }
    best
}

/// The walls drawn once on a transparent layer, kept while the view, the
/// walls, the selection and the seed stay the same.
///
/// Walls do not move while robots run, but a world of thousands of walls
/// costs far more to stroke than the rest of a frame; composing a cached
/// layer costs one pass over the pixels whatever the number of walls.
/// Source-over is associative, so walls drawn on a transparent layer and
/// then laid over the picture look as walls drawn straight onto it (up to
/// the rounding of 8-bit premultiplied colour). The layer also keeps its
/// runs of covered pixels, so that laying it over visits only those (a
/// fraction of the picture) instead of testing every pixel every frame.
#[derive(Default)]
pub struct WallLayer {
    key: u64,
    layer: Option<Pixmap>,
    /// `(first pixel, pixel count)` of each run of non-transparent pixels.
    runs: Vec<(usize, usize)>,
}

impl WallLayer {
    /// What the layer depends on, hashed (`DefaultHasher::new()` has fixed
    /// keys: the same inputs give the same key in every run).
    fn key_of(scenario: &Scenario, o: &RenderOptions) -> u64 {
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        (o.width, o.height, o.selected_wall, scenario.seed).hash(&mut h);
        for v in [o.center[0], o.center[1], o.scale] {
            v.to_bits().hash(&mut h);
        }
        for w in &scenario.walls {
            for v in w.from.iter().chain(&w.to) {
                v.to_bits().hash(&mut h);
            }
            w.texture.hash(&mut h);
        }
        h.finish()
    }

    /// Draws the walls onto `pm`, from the layer when it is still valid.
    fn draw(&mut self, pm: &mut Pixmap, o: &RenderOptions, scenario: &Scenario) {
        let key = Self::key_of(scenario, o);
        let fits = matches!(&self.layer, Some(l) if l.width() == o.width && l.height() == o.height);
        if !fits || self.key != key {
            let Some(mut layer) = Pixmap::new(o.width, o.height) else {
                draw_walls(pm, o, scenario);
                return;
            };
            draw_walls(&mut layer, o, scenario);
            self.runs = covered_runs(layer.data());
            self.layer = Some(layer);
            self.key = key;
        }
        if let Some(layer) = &self.layer {
            let (dst, src) = (pm.data_mut(), layer.data());
            for &(start, len) in &self.runs {
                let span = 4 * start..4 * (start + len);
                over(&mut dst[span.clone()], &src[span]);
            }
        }
    }
}

/// Runs of pixels whose alpha is not zero in premultiplied RGBA8 `data`:
/// `(first pixel, pixel count)`, in order.
fn covered_runs(data: &[u8]) -> Vec<(usize, usize)> {
    let mut runs = Vec::new();
    let mut open: Option<usize> = None;
    for (i, px) in data.chunks_exact(4).enumerate() {
        match (px[3] != 0, open) {
            (true, None) => open = Some(i),
            (false, Some(start)) => {
                runs.push((start, i - start));
                open = None;
            }
            _ => {}
        }
    }
    if let Some(start) = open {
        runs.push((start, data.len() / 4 - start));
    }
    runs
}

/// `dst = src over dst` for premultiplied RGBA8 pixels of the same size:
/// `dst + src − dst·αsrc/255` per channel, rounded. Written out rather than
/// through tiny-skia's pattern pipeline (which samples the layer as an
/// image) because most of a wall layer is empty and is skipped here, and a
/// covered pixel is copied.
fn over(dst: &mut [u8], src: &[u8]) {
    for (d, s) in dst.chunks_exact_mut(4).zip(src.chunks_exact(4)) {
        match s[3] {
            0 => {}
            255 => d.copy_from_slice(s),
            a => {
                let keep = 255 - a as u32;
                for (dc, sc) in d.iter_mut().zip(s) {
                    *dc = (*sc as u32 + (*dc as u32 * keep + 127) / 255) as u8;
                }
            }
        }
    }
}

/// Renders the scenario (and the running simulation, if any) into `pm`,
/// which must be `opts.width × opts.height`. Layers go bottom to top: the
/// grid, the trajectories, the walls, the sensors, the robots, the camera
/// marker and the scale bar.
pub fn render_world(
    pm: &mut Pixmap,
    scenario: &Scenario,
    sim: Option<&Simulation>,
    opts: &RenderOptions,
) {
    render_world_cached(pm, scenario, sim, opts, &mut ViewLayers::default());
}

/// What a view keeps drawn between redraws: the walls and the robots' paths.
#[derive(Default)]
pub struct ViewLayers {
    pub walls: WallLayer,
    pub trails: TrailLayer,
}

/// [`render_world`] with the walls and the robots' paths kept in `layers`
/// between calls (the page's view redrawn every frame).
pub fn render_world_cached(
    pm: &mut Pixmap,
    scenario: &Scenario,
    sim: Option<&Simulation>,
    opts: &RenderOptions,
    layers: &mut ViewLayers,
) {
    pm.fill(Color::from_rgba8(250, 250, 247, 255));
    let o = opts;
    if o.layers.grid {
        draw_grid(pm, o);
    }
    // Trajectories under everything else.
    if let Some(sim) = sim {
        layers.trails.draw(pm, o, sim);
    }
    layers.walls.draw(pm, o, scenario);
    draw_preview_wall(pm, o);
    // Sensors, then robots on top.
    let poses: Vec<Pose2> = match sim {
        Some(sim) => sim.robots.iter().map(|r| r.truth).collect(),
        None => scenario.robots.iter().map(|r| r.start_pose()).collect(),
    };
    if let Some(sim) = sim {
        draw_sensors(pm, o, sim);
    }
    let problems: Vec<usize> = if sim.is_none() {
        misplaced_robots(scenario)
    } else {
        Vec::new()
    };
    draw_robots(pm, o, &poses, &problems);
    if let Some(marker) = o.marker {
        draw_marker(pm, o, marker);
    }
    draw_scale_bar(pm, o);
}

/// The metric grid: every `grid_step_m`, a darker line every fifth.
fn draw_grid(pm: &mut Pixmap, o: &RenderOptions) {
    let (w, h) = (o.width as f64, o.height as f64);
    let world_lo = DVec2::new(
        o.center[0] - w / 2.0 / o.scale,
        o.center[1] - h / 2.0 / o.scale,
    );
    let world_hi = DVec2::new(
        o.center[0] + w / 2.0 / o.scale,
        o.center[1] + h / 2.0 / o.scale,
    );
    // Axis-aligned 1 px lines: filled as pixel-aligned rectangles, which
    // is an order of magnitude cheaper than stroking long thin paths.
    let step = grid_step_m(o.scale);
    let (minor, major) = (paint([225, 225, 220], 1.0), paint([200, 200, 195], 1.0));
    let mut x = (world_lo.x / step).floor() * step;
    while x <= world_hi.x {
        let (px, _) = o.to_px(DVec2::new(x, 0.0));
        let is_major = ((x / step).round() as i64) % 5 == 0;
        if let Some(r) = Rect::from_xywh(px.floor(), 0.0, 1.0, o.height as f32) {
            pm.fill_rect(
                r,
                if is_major { &major } else { &minor },
                Transform::identity(),
                None,
            );
        }
        x += step;
    }
    let mut y = (world_lo.y / step).floor() * step;
    while y <= world_hi.y {
        let (_, py) = o.to_px(DVec2::new(0.0, y));
        let is_major = ((y / step).round() as i64) % 5 == 0;
        if let Some(r) = Rect::from_xywh(0.0, py.floor(), o.width as f32, 1.0) {
            pm.fill_rect(
                r,
                if is_major { &major } else { &minor },
                Transform::identity(),
                None,
            );
        }
        y += step;
    }
}

/// The walls (outlined, tinted with their texture's hint colour), the
/// selected one highlighted, and the wall being drawn.
fn draw_walls(pm: &mut Pixmap, o: &RenderOptions, scenario: &Scenario) {
    let wall_px = (0.06 * o.scale).clamp(2.0, 8.0) as f32;
    let outline = paint([40, 40, 40], 1.0);
    for (i, wall) in scenario.walls.iter().enumerate() {
        let seg = [DVec2::from(wall.from), DVec2::from(wall.to)];
        if o.selected_wall == Some(i) {
            polyline(
                pm,
                o,
                seg.into_iter(),
                0.0,
                &paint([255, 200, 0], 0.9),
                &stroke(wall_px + 8.0),
            );
        }
        polyline(
            pm,
            o,
            seg.into_iter(),
            0.0,
            &outline,
            &stroke(wall_px + 2.0),
        );
        let hint = texture_hint(wall.texture.as_deref(), i, scenario.seed);
        polyline(
            pm,
            o,
            seg.into_iter(),
            0.0,
            &paint(hint, 1.0),
            &stroke(wall_px),
        );
    }
}

/// The wall being drawn with the Wall tool, dashed.
fn draw_preview_wall(pm: &mut Pixmap, o: &RenderOptions) {
    if let Some(p) = o.preview_wall {
        let mut s = stroke(3.0);
        s.dash = StrokeDash::new(vec![8.0, 5.0], 0.0);
        polyline(
            pm,
            o,
            [DVec2::new(p[0], p[1]), DVec2::new(p[2], p[3])].into_iter(),
            0.0,
            &paint([30, 90, 200], 0.9),
            &s,
        );
    }
}

/// Sonar cones and laser rays at the robots' true poses.
fn draw_sensors(pm: &mut Pixmap, o: &RenderOptions, sim: &Simulation) {
    for (i, r) in sim.robots.iter().enumerate() {
        if o.layers.sonar {
            let half = (r.sonar_cone_rad() / 2.0).max(0.02);
            for k in 0..SONAR_COUNT {
                let (origin, axis) = Sonar::axis(&r.truth, k);
                let range = r.last_sonar.ranges_m[k];
                let mut pts = vec![origin];
                for j in 0..=6 {
                    let a = axis - half + 2.0 * half * j as f64 / 6.0;
                    pts.push(origin + DVec2::new(a.cos(), a.sin()) * range);
                }
                let echo = !r.last_sonar.no_echo[k];
                polygon(
                    pm,
                    o,
                    &pts,
                    Some(&paint(
                        if echo { [60, 170, 90] } else { [160, 200, 170] },
                        0.18,
                    )),
                    Some((&paint([40, 130, 70], 0.5), &stroke(1.0))),
                );
            }
        }
        if o.layers.laser {
            let rays = sim.robots.len() <= RAY_ROBOTS || o.selected_robot == Some(i);
            draw_laser(pm, o, r, rays);
        }
    }
}

/// With more robots than this, only the selected robot's laser is drawn as
/// rays; the others' as a fan (see [`draw_laser`]).
pub const RAY_ROBOTS: usize = 4;

/// One robot's last laser scan. As rays (`rays`): every beam a thin
/// anti-aliased line, fainter where it reached its maximum range, and a dot
/// where it hit. As a fan: the area the scan swept as one translucent
/// polygon through the beams' end points, with the hit dots, drawn without
/// anti-aliasing. Sixteen robots' 181 anti-aliased rays took most of the
/// world view's drawing time (issue 22: 37 ms a drawing); a fan shows the
/// same reach and the same hits at a small fraction of that.
fn draw_laser(pm: &mut Pixmap, o: &RenderOptions, r: &RobotSim, rays: bool) {
    let origin = r.truth.position();
    let (mut hits, mut misses) = (Vec::new(), Vec::new());
    let mut fan = vec![origin];
    let mut dots = PathBuilder::new();
    for b in 0..r.last_scan.ranges_m.len() {
        let a = r.truth.theta + beam_bearing(b);
        let end = origin + DVec2::new(a.cos(), a.sin()) * r.last_scan.ranges_m[b];
        fan.push(end);
        if r.last_scan.max_range[b] {
            misses.push((origin, end));
        } else {
            hits.push((origin, end));
            let (x, y) = o.to_px(end);
            if let Some(rect) = Rect::from_xywh(x - 1.5, y - 1.5, 3.0, 3.0) {
                dots.push_rect(rect);
            }
        }
    }
    let mut dot_paint = paint([200, 20, 20], 0.9);
    if rays {
        let mut s1 = stroke(1.0);
        s1.line_cap = LineCap::Butt;
        segments(pm, o, &misses, &paint([220, 40, 40], 0.07), &s1);
        segments(pm, o, &hits, &paint([220, 40, 40], 0.22), &s1);
    } else {
        let mut fill = paint([220, 40, 40], 0.2);
        fill.anti_alias = false;
        polygon(pm, o, &fan, Some(&fill), None);
        dot_paint.anti_alias = false;
    }
    if let Some(path) = dots.finish() {
        pm.fill_path(
            &path,
            &dot_paint,
            FillRule::Winding,
            Transform::identity(),
            None,
        );
    }
}

/// Indices of the robots a placement problem names (`robots[i]...`).
fn misplaced_robots(scenario: &Scenario) -> Vec<usize> {
    scenario
        .placement_problems()
        .iter()
        .filter_map(|p| {
            p.field
                .strip_prefix("robots[")
                .and_then(|s| s.split(']').next())
                .and_then(|s| s.parse().ok())
        })
        .collect()
}

/// The robots' bodies with a heading arrow; the selected one
/// highlighted, misplaced ones outlined in red.
fn draw_robots(pm: &mut Pixmap, o: &RenderOptions, poses: &[Pose2], problems: &[usize]) {
    for (i, pose) in poses.iter().enumerate() {
        let c = robot_colour(i);
        let body = P2dx::body(pose);
        if o.selected_robot == Some(i) {
            polygon(
                pm,
                o,
                &body.corners,
                None,
                Some((&paint([255, 200, 0], 0.9), &stroke(6.0))),
            );
        }
        let edge = if problems.contains(&i) {
            (paint([230, 0, 0], 1.0), stroke(3.0))
        } else {
            (paint([20, 20, 20], 1.0), stroke(1.2))
        };
        polygon(
            pm,
            o,
            &body.corners,
            Some(&paint(c, 1.0)),
            Some((&edge.0, &edge.1)),
        );
        // Heading: a white arrow head at the front.
        let hl = P2dx::BODY_LENGTH_M / 2.0;
        let tri = [
            pose.transform_point(DVec2::new(hl - 0.02, 0.0)),
            pose.transform_point(DVec2::new(hl - 0.17, 0.09)),
            pose.transform_point(DVec2::new(hl - 0.17, -0.09)),
        ];
        polygon(pm, o, &tri, Some(&paint([255, 255, 255], 1.0)), None);
    }
}

/// Where a camera frame was taken: the field of view as a wedge.
fn draw_marker(pm: &mut Pixmap, o: &RenderOptions, [x, y, th]: [f64; 3]) {
    let p = DVec2::new(x, y);
    let reach = 2.5;
    let h = o.marker_fov / 2.0;
    let wedge = [
        p,
        p + DVec2::from_angle(th + h) * reach,
        p + DVec2::from_angle(th - h) * reach,
    ];
    polygon(
        pm,
        o,
        &wedge,
        Some(&paint([255, 190, 0], 0.25)),
        Some((&paint([200, 120, 0], 1.0), &stroke(2.0))),
    );
    let (cx, cy) = o.to_px(p);
    let mut pb = PathBuilder::new();
    pb.push_circle(cx, cy, 6.0);
    if let Some(path) = pb.finish() {
        pm.fill_path(
            &path,
            &paint([200, 120, 0], 1.0),
            FillRule::Winding,
            Transform::identity(),
            None,
        );
    }
}

/// The scale bar, bottom left (its label is drawn by the page).
fn draw_scale_bar(pm: &mut Pixmap, o: &RenderOptions) {
    let bar_m = scale_bar_m(o.scale);
    let bar_px = (bar_m * o.scale) as f32;
    let y0 = o.height as f32 - 18.0;
    if let Some(rect) = Rect::from_xywh(14.0, y0, bar_px, 5.0) {
        pm.fill_rect(rect, &paint([30, 30, 30], 1.0), Transform::identity(), None);
    }
}

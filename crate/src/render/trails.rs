//! # The robots' trajectories, drawn once
//!
//! The world view shows every robot's true path and the path its odometry
//! believes, from the start of the run. Stroking them whole at every redraw
//! costs time in proportion to the run's length: sixteen robots' paths took
//! 3 ms to draw 10 s into a run, 13 ms at 150 s and 37 ms at 600 s (native;
//! `examples/bench_sim.rs --late`), so an hour's run would have spent
//! a quarter of a second a frame on them.
//!
//! A [`TrailLayer`] keeps the paths drawn on a transparent layer and, at each
//! redraw, strokes only what the robots added since the last one, then lays
//! the layer over the picture: the work of a frame no longer grows with the
//! run. Because source-over composition is associative, paths stroked onto a
//! transparent layer and laid over the picture look as paths stroked straight
//! onto it (up to 8-bit rounding). Two differences remain, both small: a path
//! that passes over itself (a robot on its second lap) is blended again where
//! the new stretch covers the old, as two strokes are, where one stroke of
//! the whole path would cover it once; and a dashed path's dashes continue
//! from one stretch to the next by their offset along it.
//!
//! A path keeps only points at least [`MIN_STEP_PX`] from the last kept one
//! (a long trajectory looks the same with a far shorter path), exactly as
//! [`super::polyline`] drops them; the newest point, if it was not kept, is
//! joined to the last kept one straight onto the picture at each redraw, so
//! that the path reaches the robot. The layer is drawn anew when the view,
//! the path layers shown or the robots change, or a robot's log is shorter
//! than what was drawn of it (a new run).

use super::{over, paint, robot_colour, stroke, RenderOptions};
use crate::geom::Pose2;
use crate::sim::Simulation;
use glam::{DVec2, Vec2};
use tiny_skia::{LineCap, LineJoin, Paint, PathBuilder, Pixmap, Stroke, StrokeDash, Transform};

/// Points closer than this to the last kept one are dropped (px).
pub const MIN_STEP_PX: f32 = 1.5;

/// The odometry path's dashes: on, off (px).
const DASH_PX: [f32; 2] = [6.0, 4.0];

/// How far one path has been drawn onto the layer.
#[derive(Clone, Debug, Default)]
struct Trail {
    /// The next point of the log to look at.
    next: usize,
    /// The last point kept (px).
    last: Option<(f32, f32)>,
    /// The newest point, when it was not kept (px).
    tip: Option<(f32, f32)>,
    /// Length of the path drawn so far (px): where its dashes stand.
    length_px: f32,
    /// The box of the points kept (px): lowest and highest corner.
    bounds: Option<(Vec2, Vec2)>,
}

impl Trail {
    /// Strokes the points from `next` on onto `layer` (see the module doc).
    fn extend(
        &mut self,
        layer: &mut Pixmap,
        o: &RenderOptions,
        points: impl Iterator<Item = DVec2>,
        style: &PathStyle,
    ) {
        let min2 = MIN_STEP_PX * MIN_STEP_PX;
        let mut pb = PathBuilder::new();
        if let Some((x, y)) = self.last {
            pb.move_to(x, y);
        }
        let (start_length, mut segments) = (self.length_px, 0);
        for w in points {
            self.next += 1;
            let (x, y) = o.to_px(w);
            match self.last {
                None => pb.move_to(x, y),
                Some((lx, ly)) if (x - lx).powi(2) + (y - ly).powi(2) >= min2 => {
                    pb.line_to(x, y);
                    self.length_px += (x - lx).hypot(y - ly);
                    segments += 1;
                }
                Some(_) => {
                    self.tip = Some((x, y));
                    continue;
                }
            }
            self.last = Some((x, y));
            self.tip = None;
            let p = Vec2::new(x, y);
            self.bounds = Some(
                self.bounds
                    .map_or((p, p), |(lo, hi)| (lo.min(p), hi.max(p))),
            );
        }
        if segments == 0 {
            return;
        }
        if let Some(path) = pb.finish() {
            let s = style.stroke(start_length);
            layer.stroke_path(&path, &style.paint, &s, Transform::identity(), None);
        }
    }

    /// Joins the newest point, if it was not kept, to the path on `pm`.
    fn draw_tip(&self, pm: &mut Pixmap, style: &PathStyle) {
        let (Some((lx, ly)), Some((x, y))) = (self.last, self.tip) else {
            return;
        };
        let mut pb = PathBuilder::new();
        pb.move_to(lx, ly);
        pb.line_to(x, y);
        if let Some(path) = pb.finish() {
            let s = style.stroke(self.length_px);
            pm.stroke_path(&path, &style.paint, &s, Transform::identity(), None);
        }
    }
}

/// How one kind of path is drawn.
struct PathStyle {
    paint: Paint<'static>,
    width: f32,
    dashed: bool,
}

impl PathStyle {
    /// Robot `i`'s odometry path: thin, dark, dashed.
    fn odometry(i: usize) -> PathStyle {
        let c = robot_colour(i);
        PathStyle {
            paint: paint([c[0] / 2, c[1] / 2, c[2] / 2], 0.8),
            width: 1.0,
            dashed: true,
        }
    }

    /// Robot `i`'s true path: solid, in its colour.
    fn truth(i: usize) -> PathStyle {
        PathStyle {
            paint: paint(robot_colour(i), 0.75),
            width: 2.0,
            dashed: false,
        }
    }

    /// The stroke of a stretch that starts `length_px` along the path.
    fn stroke(&self, length_px: f32) -> Stroke {
        if !self.dashed {
            return Stroke {
                width: self.width,
                line_join: LineJoin::Bevel,
                ..Stroke::default()
            };
        }
        let mut s = stroke(self.width);
        s.line_join = LineJoin::Bevel;
        s.line_cap = LineCap::Butt;
        let period = DASH_PX[0] + DASH_PX[1];
        s.dash = StrokeDash::new(DASH_PX.to_vec(), length_px % period);
        s
    }
}

/// Lays `layer` over `pm` within the box `lo`..`hi` (px), widened by a
/// stroke's reach: the rest of the layer is empty.
fn lay_over(pm: &mut Pixmap, layer: &Pixmap, lo: Vec2, hi: Vec2) {
    let (w, h) = (pm.width() as f32, pm.height() as f32);
    let reach = 4.0; // half the widest stroke, antialiasing and a bevel's corner
    let (x0, x1) = (
        (lo.x - reach).clamp(0.0, w),
        (hi.x + reach + 1.0).clamp(0.0, w),
    );
    let (y0, y1) = (
        (lo.y - reach).clamp(0.0, h),
        (hi.y + reach + 1.0).clamp(0.0, h),
    );
    let (x0, x1, y0, y1) = (x0 as usize, x1 as usize, y0 as usize, y1 as usize);
    if x0 >= x1 {
        return;
    }
    let stride = 4 * pm.width() as usize;
    let (dst, src) = (pm.data_mut(), layer.data());
    for y in y0..y1 {
        let row = y * stride + 4 * x0..y * stride + 4 * x1;
        over(&mut dst[row.clone()], &src[row]);
    }
}

/// The robots' paths kept drawn between redraws (see the module doc).
#[derive(Default)]
pub struct TrailLayer {
    key: u64,
    layer: Option<Pixmap>,
    /// Per robot: its odometry path and its true path.
    trails: Vec<[Trail; 2]>,
}

impl TrailLayer {
    /// What the layer depends on besides the logs, hashed
    /// (`DefaultHasher::new()` has fixed keys).
    fn key_of(o: &RenderOptions, robots: usize) -> u64 {
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        (o.width, o.height, robots).hash(&mut h);
        (o.layers.odometry_path, o.layers.truth_path).hash(&mut h);
        for v in [o.center[0], o.center[1], o.scale] {
            v.to_bits().hash(&mut h);
        }
        h.finish()
    }

    /// Draws the robots' paths onto `pm`, stroking only what is new.
    pub fn draw(&mut self, pm: &mut Pixmap, o: &RenderOptions, sim: &Simulation) {
        let key = Self::key_of(o, sim.robots.len());
        let fits = matches!(&self.layer, Some(l) if l.width() == o.width && l.height() == o.height);
        let shrunk = self
            .trails
            .iter()
            .zip(&sim.robots)
            .any(|(t, r)| t[0].next > r.log.odometry.len() || t[1].next > r.log.truth.len());
        if !fits || self.key != key || shrunk {
            self.layer = Pixmap::new(o.width, o.height);
            self.trails = vec![Default::default(); sim.robots.len()];
            self.key = key;
        }
        let Some(layer) = &mut self.layer else {
            return;
        };
        for (i, (r, [odometry, truth])) in sim.robots.iter().zip(&mut self.trails).enumerate() {
            if o.layers.odometry_path && r.log.odometry.len() > 1 {
                let start = r.spec.start_pose();
                let new = r.log.odometry[odometry.next..].iter();
                let points = new.map(|p: &Pose2| start.compose(p).position());
                odometry.extend(layer, o, points, &PathStyle::odometry(i));
            }
            if o.layers.truth_path && r.log.truth.len() > 1 {
                let points = r.log.truth[truth.next..].iter().map(|p| p.position());
                truth.extend(layer, o, points, &PathStyle::truth(i));
            }
        }
        let bounds = self.trails.iter().flatten().filter_map(|t| t.bounds);
        let bounds = bounds.reduce(|(a, b), (c, d)| (a.min(c), b.max(d)));
        if let Some((lo, hi)) = bounds {
            lay_over(pm, layer, lo, hi);
        }
        for (i, [odometry, truth]) in self.trails.iter().enumerate() {
            odometry.draw_tip(pm, &PathStyle::odometry(i));
            truth.draw_tip(pm, &PathStyle::truth(i));
        }
    }
}

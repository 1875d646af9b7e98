//! # Plane geometry: poses, segments and exact ray casting
//!
//! Everything the simulator knows about space is built from two things: a
//! [`Pose2`] (a position and a heading) and a [`Segment`] (a wall, or one edge
//! of a robot's body). Range sensors are modelled by *exact* ray–segment
//! intersection: a laser beam is the ray `o + t·d` (`t ≥ 0`, `|d| = 1`), and
//! its range is the smallest `t` at which it meets a segment.
//!
//! ## Ray against segment
//! A segment is `a + u·(b − a)` with `u ∈ [0, 1]`. Setting
//! `o + t·d = a + u·e` (with `e = b − a`) and taking 2-D cross products
//! (`p × q = p.x·q.y − p.y·q.x`) with `e` and with `d` eliminates one unknown
//! each:
//!
//! ```text
//! t = ((a − o) × e) / (d × e)        u = ((a − o) × d) / (d × e)
//! ```
//!
//! When `d × e = 0` the ray is parallel to the segment and, for a sensor,
//! sees nothing (a grazing beam has no surface to return from).
//!
//! Conventions: metres and radians; x right, y up, θ counter-clockwise from
//! +x. Angles are kept in (−π, π] by [`wrap_angle`].

use glam::DVec2;
use std::f64::consts::PI;

/// Wraps an angle into (−π, π].
pub fn wrap_angle(theta_rad: f64) -> f64 {
    let mut a = theta_rad % (2.0 * PI);
    if a <= -PI {
        a += 2.0 * PI;
    } else if a > PI {
        a -= 2.0 * PI;
    }
    a
}

/// 2-D cross product (the z component of the 3-D one).
#[inline]
pub fn cross(p: DVec2, q: DVec2) -> f64 {
    p.x * q.y - p.y * q.x
}

/// A planar pose: where a robot (or a frame) is and which way it faces.
#[derive(Clone, Copy, Debug, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct Pose2 {
    pub x: f64,
    pub y: f64,
    pub theta: f64,
}

/// A pose ready to map points: [`Pose2::frame`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PoseFrame {
    x: f64,
    y: f64,
    s: f64,
    c: f64,
}

impl PoseFrame {
    /// [`Pose2::transform_point`].
    pub fn to_parent(&self, local: DVec2) -> DVec2 {
        let (s, c) = (self.s, self.c);
        DVec2::new(
            self.x + c * local.x - s * local.y,
            self.y + s * local.x + c * local.y,
        )
    }

    /// A direction of the local frame in the parent frame (rotation only).
    pub fn rotate(&self, v: DVec2) -> DVec2 {
        let (s, c) = (self.s, self.c);
        DVec2::new(c * v.x - s * v.y, s * v.x + c * v.y)
    }

    /// [`Pose2::inverse_transform_point`].
    pub fn to_local(&self, p: DVec2) -> DVec2 {
        let (s, c) = (self.s, self.c);
        let d = p - DVec2::new(self.x, self.y);
        DVec2::new(c * d.x + s * d.y, -s * d.x + c * d.y)
    }
}

impl Pose2 {
    pub const IDENTITY: Pose2 = Pose2 {
        x: 0.0,
        y: 0.0,
        theta: 0.0,
    };

    pub fn new(x: f64, y: f64, theta: f64) -> Self {
        Pose2 { x, y, theta }
    }

    pub fn position(&self) -> DVec2 {
        DVec2::new(self.x, self.y)
    }

    /// Unit vector along the heading.
    pub fn heading(&self) -> DVec2 {
        DVec2::new(self.theta.cos(), self.theta.sin())
    }

    /// Maps a point given in this pose's local frame into the parent frame.
    pub fn transform_point(&self, local: DVec2) -> DVec2 {
        self.frame().to_parent(local)
    }

    /// Maps a point of the parent frame into this pose's local frame.
    pub fn inverse_transform_point(&self, p: DVec2) -> DVec2 {
        self.frame().to_local(p)
    }

    /// The pose with its heading's sine and cosine worked out once, for
    /// mapping many points (the same numbers as the one-point methods).
    pub fn frame(&self) -> PoseFrame {
        let (s, c) = self.theta.sin_cos();
        PoseFrame {
            x: self.x,
            y: self.y,
            s,
            c,
        }
    }

    /// Pose composition `self ⊕ other`: `other` is expressed in `self`'s frame.
    pub fn compose(&self, other: &Pose2) -> Pose2 {
        let p = self.transform_point(other.position());
        Pose2::new(p.x, p.y, wrap_angle(self.theta + other.theta))
    }

    /// The inverse pose: `self ⊕ self.inverse() = identity`.
    pub fn inverse(&self) -> Pose2 {
        let (s, c) = self.theta.sin_cos();
        Pose2::new(
            -c * self.x - s * self.y,
            s * self.x - c * self.y,
            wrap_angle(-self.theta),
        )
    }

    /// `other` expressed in this pose's frame: `self.inverse() ⊕ other`.
    pub fn between(&self, other: &Pose2) -> Pose2 {
        self.inverse().compose(other)
    }

    pub fn is_finite(&self) -> bool {
        self.x.is_finite() && self.y.is_finite() && self.theta.is_finite()
    }
}

/// A line segment from `a` to `b`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    pub a: DVec2,
    pub b: DVec2,
}

impl Segment {
    pub fn new(a: DVec2, b: DVec2) -> Self {
        Segment { a, b }
    }

    pub fn length(&self) -> f64 {
        (self.b - self.a).length()
    }

    /// Distance along the unit ray `origin + t·dir` to this segment, if the
    /// ray meets it at `t ≥ 0`. Parallel rays return `None`.
    #[inline]
    pub fn ray_hit(&self, origin: DVec2, dir: DVec2) -> Option<f64> {
        let e = self.b - self.a;
        let denom = cross(dir, e);
        if denom.abs() < 1e-12 {
            return None;
        }
        let ao = self.a - origin;
        let t = cross(ao, e) / denom;
        let u = cross(ao, dir) / denom;
        if t >= 0.0 && (0.0..=1.0).contains(&u) {
            Some(t)
        } else {
            None
        }
    }

    /// The point of the segment closest to `p`.
    pub fn closest_point(&self, p: DVec2) -> DVec2 {
        let e = self.b - self.a;
        let len2 = e.length_squared();
        if len2 == 0.0 {
            return self.a;
        }
        let u = ((p - self.a).dot(e) / len2).clamp(0.0, 1.0);
        self.a + e * u
    }

    /// Euclidean distance from `p` to the segment.
    pub fn distance_to_point(&self, p: DVec2) -> f64 {
        (p - self.closest_point(p)).length()
    }

    /// Whether two segments share at least one point (touching counts).
    pub fn intersects(&self, other: &Segment) -> bool {
        let d1 = cross(self.b - self.a, other.a - self.a);
        let d2 = cross(self.b - self.a, other.b - self.a);
        let d3 = cross(other.b - other.a, self.a - other.a);
        let d4 = cross(other.b - other.a, self.b - other.a);
        if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
            && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
        {
            return true;
        }
        let on = |s: &Segment, p: DVec2, d: f64| d == 0.0 && s.closest_point(p).distance(p) < 1e-12;
        on(self, other.a, d1)
            || on(self, other.b, d2)
            || on(other, self.a, d3)
            || on(other, self.b, d4)
    }

    /// Smallest distance between two segments (0 when they intersect).
    pub fn distance_to_segment(&self, other: &Segment) -> f64 {
        if self.intersects(other) {
            return 0.0;
        }
        self.distance_to_point(other.a)
            .min(self.distance_to_point(other.b))
            .min(other.distance_to_point(self.a))
            .min(other.distance_to_point(self.b))
    }

    /// Axis-aligned bounding box as (min, max).
    pub fn bounds(&self) -> (DVec2, DVec2) {
        (self.a.min(self.b), self.a.max(self.b))
    }
}

/// A convex polygon given by its corners in counter-clockwise order, used for
/// robot bodies.
#[derive(Clone, Debug, PartialEq)]
pub struct ConvexPolygon {
    pub corners: Vec<DVec2>,
}

impl ConvexPolygon {
    /// The rectangle of `length × width` centred on `pose`, long side along
    /// the heading.
    pub fn rectangle(pose: &Pose2, length: f64, width: f64) -> Self {
        let (hl, hw) = (length / 2.0, width / 2.0);
        let corners = [
            DVec2::new(hl, hw),
            DVec2::new(-hl, hw),
            DVec2::new(-hl, -hw),
            DVec2::new(hl, -hw),
        ]
        .iter()
        .map(|&c| pose.transform_point(c))
        .collect();
        ConvexPolygon { corners }
    }

    pub fn edges(&self) -> impl Iterator<Item = Segment> + '_ {
        let n = self.corners.len();
        (0..n).map(move |i| Segment::new(self.corners[i], self.corners[(i + 1) % n]))
    }

    /// Whether `p` lies inside or on the boundary.
    pub fn contains(&self, p: DVec2) -> bool {
        self.edges().all(|e| cross(e.b - e.a, p - e.a) >= 0.0)
    }

    /// Smallest distance from the polygon (boundary or interior) to a segment;
    /// 0 when they touch or overlap.
    pub fn distance_to_segment(&self, s: &Segment) -> f64 {
        if self.contains(s.a) || self.contains(s.b) {
            return 0.0;
        }
        self.edges()
            .map(|e| e.distance_to_segment(s))
            .fold(f64::INFINITY, f64::min)
    }

    /// Whether two convex polygons overlap or touch.
    pub fn touches(&self, other: &ConvexPolygon) -> bool {
        other.edges().any(|e| self.distance_to_segment(&e) == 0.0)
            || self.contains(other.corners[0])
            || other.contains(self.corners[0])
    }

    pub fn bounds(&self) -> (DVec2, DVec2) {
        let mut lo = DVec2::splat(f64::INFINITY);
        let mut hi = DVec2::splat(f64::NEG_INFINITY);
        for &c in &self.corners {
            lo = lo.min(c);
            hi = hi.max(c);
        }
        (lo, hi)
    }
}

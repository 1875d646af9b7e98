//! # The scenario file
//!
//! A scenario is everything a run depends on: the walls, the robots and where
//! they start, the noise, and the seed. Its JSON form is fixed by the
//! interface contract, `docs/interfaces.md`, and documented, with every
//! default, in the README. A run is a pure function of the scenario (and its seed).
//!
//! Parsing goes in two layers so that every error names the field at fault
//! (`robots[1].start: …`):
//! 1. [`Scenario::parse`] checks the *shape*: known keys only, types, finite
//!    numbers, ranges, counts, duplicate names, zero-length walls.
//! 2. [`Scenario::placement_problems`] checks the *placement*: robots that
//!    start inside or touching a wall, or overlapping each other. The page
//!    keeps such a scenario (the user is mid-edit) and shows the problem; a
//!    run refuses it. [`Scenario::from_json`] applies both.

use crate::geom::{ConvexPolygon, Pose2, Segment};
use crate::kinematics::P2dx;
use glam::DVec2;
use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};
use std::fmt;

/// At most this many robots in one scenario.
pub const MAX_ROBOTS: usize = 16;
/// At most this many walls in one scenario.
pub const MAX_WALLS: usize = 10_000;
/// Longest run a scenario may ask for, in simulated seconds.
pub const MAX_DURATION_S: f64 = 3600.0;
/// Coordinates must lie within ±this many metres.
pub const MAX_COORD_M: f64 = 1000.0;

/// A validation error: the offending field (a JSON path such as
/// `robots[1].start`) and what is wrong with it.
#[derive(Clone, Debug, PartialEq)]
pub struct ScenarioError {
    pub field: String,
    pub message: String,
}

impl ScenarioError {
    fn new(field: impl Into<String>, message: impl Into<String>) -> Self {
        ScenarioError {
            field: field.into(),
            message: message.into(),
        }
    }
}

impl fmt::Display for ScenarioError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.field.is_empty() {
            write!(f, "{}", self.message)
        } else {
            write!(f, "{}: {}", self.field, self.message)
        }
    }
}

impl std::error::Error for ScenarioError {}

/// Which side the followed wall is on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FollowSide {
    Left,
    Right,
}

impl FollowSide {
    /// +1 for left, −1 for right: the sign of the side's y in the robot frame.
    pub fn sign(self) -> f64 {
        match self {
            FollowSide::Left => 1.0,
            FollowSide::Right => -1.0,
        }
    }
}

/// One wall: a segment with an optional texture name.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WallSpec {
    pub from: [f64; 2],
    pub to: [f64; 2],
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub texture: Option<String>,
}

impl WallSpec {
    pub fn segment(&self) -> Segment {
        Segment::new(DVec2::from(self.from), DVec2::from(self.to))
    }
}

/// One robot: its name, start pose in the world, and how it follows walls.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RobotSpec {
    pub name: String,
    /// `[x, y, theta]` in the world frame.
    pub start: [f64; 3],
    pub follow: FollowSide,
    /// Clearance held to the followed wall, as the side sonar reads it (m).
    pub distance: f64,
    /// Cruise speed (m/s).
    pub speed: f64,
}

impl RobotSpec {
    pub fn start_pose(&self) -> Pose2 {
        Pose2::new(self.start[0], self.start[1], self.start[2])
    }
}

/// Odometry and range-sensor noise. All zero gives a noise-free run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct NoiseSpec {
    /// Random wheel slip: each step, each wheel's encoder reading is off by a
    /// Gaussian with this standard deviation times the distance it rolled.
    pub wheel_slip: f64,
    /// Systematic encoder scale error `[left, right]`: the encoder reports
    /// `(1 + e)` times the true travel (a worn or mis-sized wheel).
    pub wheel_scale_error: [f64; 2],
    /// Systematic wheelbase error: the robot computes its turns with a
    /// wheelbase `(1 + e)` times the true one.
    pub wheelbase_error: f64,
    /// Sonar range noise, standard deviation in metres.
    pub sonar_std_m: f64,
    /// Laser range noise, standard deviation in metres.
    pub laser_std_m: f64,
}

impl Default for NoiseSpec {
    fn default() -> Self {
        NoiseSpec {
            wheel_slip: 0.01,
            wheel_scale_error: [0.0005, -0.0005],
            wheelbase_error: 0.01,
            sonar_std_m: 0.02,
            laser_std_m: 0.01,
        }
    }
}

impl NoiseSpec {
    /// No noise at all: odometry equals the truth, ranges are exact.
    pub fn zero() -> Self {
        NoiseSpec {
            wheel_slip: 0.0,
            wheel_scale_error: [0.0, 0.0],
            wheelbase_error: 0.0,
            sonar_std_m: 0.0,
            laser_std_m: 0.0,
        }
    }
}

/// Range-sensor settings. Bearings and beam counts are the P2DX's and fixed:
/// 8 sonars at ±90, ±50, ±30, ±10 degrees; 181 laser beams over 180 degrees.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SensorSpec {
    pub sonar_range_m: f64,
    /// Full opening angle of each sonar's beam cone.
    pub sonar_cone_deg: f64,
    pub laser_range_m: f64,
}

impl Default for SensorSpec {
    fn default() -> Self {
        SensorSpec {
            sonar_range_m: 2.0,
            sonar_cone_deg: 15.0,
            laser_range_m: 4.0,
        }
    }
}

/// The robots' camera (all robots carry the same model).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CameraSpec {
    /// Image size in pixels (16 … 640 × 16 … 480).
    pub width: u32,
    pub height: u32,
    /// Horizontal field of view (degrees).
    pub hfov_deg: f64,
    /// Height of the optical centre above the floor (m).
    pub mount_height_m: f64,
    /// Height of every wall (m).
    pub wall_height_m: f64,
    /// Per-pixel Gaussian noise, standard deviation in grey levels.
    pub pixel_noise_std: f64,
    /// Per-frame exposure change: standard deviation of the gain around 1.
    pub exposure_jitter: f64,
    /// A frame is captured every this many simulated seconds.
    pub period_s: f64,
}

impl Default for CameraSpec {
    fn default() -> Self {
        CameraSpec {
            width: 320,
            height: 240,
            hfov_deg: 60.0,
            mount_height_m: 0.4,
            wall_height_m: 2.5,
            pixel_noise_std: 2.0,
            exposure_jitter: 0.03,
            period_s: 1.0,
        }
    }
}

/// A whole scenario, with every default filled in.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Scenario {
    pub name: String,
    pub seed: u64,
    pub duration_s: f64,
    pub walls: Vec<WallSpec>,
    pub robots: Vec<RobotSpec>,
    pub noise: NoiseSpec,
    pub sensors: SensorSpec,
    pub camera: CameraSpec,
}

pub const DEFAULT_NAME: &str = "untitled";
pub const DEFAULT_SEED: u64 = 1;
pub const DEFAULT_DURATION_S: f64 = 300.0;
pub const DEFAULT_DISTANCE_M: f64 = 0.6;
pub const DEFAULT_SPEED_MPS: f64 = 0.35;

// ---------------------------------------------------------------------------
// Reading JSON values with the path of each field at hand.

fn type_name(v: &Value) -> &'static str {
    match v {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "an array",
        Value::Object(_) => "an object",
    }
}

fn as_object<'a>(v: &'a Value, path: &str) -> Result<&'a Map<String, Value>, ScenarioError> {
    v.as_object().ok_or_else(|| {
        ScenarioError::new(path, format!("expected an object, found {}", type_name(v)))
    })
}

fn check_keys(map: &Map<String, Value>, path: &str, known: &[&str]) -> Result<(), ScenarioError> {
    for key in map.keys() {
        if !known.contains(&key.as_str()) {
            let field = if path.is_empty() {
                key.clone()
            } else {
                format!("{path}.{key}")
            };
            return Err(ScenarioError::new(
                field,
                format!("unknown key (expected one of: {})", known.join(", ")),
            ));
        }
    }
    Ok(())
}

fn join(path: &str, key: &str) -> String {
    if path.is_empty() {
        key.to_string()
    } else {
        format!("{path}.{key}")
    }
}

fn number(v: &Value, path: &str) -> Result<f64, ScenarioError> {
    let x = v.as_f64().ok_or_else(|| {
        ScenarioError::new(path, format!("expected a number, found {}", type_name(v)))
    })?;
    if !x.is_finite() {
        return Err(ScenarioError::new(path, "must be a finite number"));
    }
    Ok(x)
}

fn number_in(v: &Value, path: &str, lo: f64, hi: f64) -> Result<f64, ScenarioError> {
    let x = number(v, path)?;
    if x < lo || x > hi {
        return Err(ScenarioError::new(
            path,
            format!("{x} is outside [{lo}, {hi}]"),
        ));
    }
    Ok(x)
}

fn numbers<const N: usize>(v: &Value, path: &str, what: &str) -> Result<[f64; N], ScenarioError> {
    let arr = v.as_array().ok_or_else(|| {
        ScenarioError::new(path, format!("expected {what}, found {}", type_name(v)))
    })?;
    if arr.len() != N {
        return Err(ScenarioError::new(
            path,
            format!(
                "expected {what} ({N} numbers), found {} elements",
                arr.len()
            ),
        ));
    }
    let mut out = [0.0; N];
    for (i, x) in arr.iter().enumerate() {
        out[i] = number(x, &format!("{path}[{i}]"))?;
        if out[i].abs() > MAX_COORD_M {
            return Err(ScenarioError::new(
                format!("{path}[{i}]"),
                format!("{} is beyond ±{MAX_COORD_M} m", out[i]),
            ));
        }
    }
    Ok(out)
}

fn string(v: &Value, path: &str) -> Result<String, ScenarioError> {
    v.as_str().map(str::to_string).ok_or_else(|| {
        ScenarioError::new(path, format!("expected a string, found {}", type_name(v)))
    })
}

fn opt<'a>(map: &'a Map<String, Value>, key: &str) -> Option<&'a Value> {
    map.get(key)
}

impl Scenario {
    /// Parses and fully validates a scenario: shape and placement. The first
    /// problem found is returned, naming its field.
    pub fn from_json(text: &str) -> Result<Scenario, ScenarioError> {
        let s = Scenario::parse(text)?;
        if let Some(p) = s.placement_problems().into_iter().next() {
            return Err(p);
        }
        Ok(s)
    }

    /// Parses a scenario and checks its shape (see the module docs), filling
    /// in defaults. Placement is checked by [`Scenario::placement_problems`].
    pub fn parse(text: &str) -> Result<Scenario, ScenarioError> {
        let value: Value = serde_json::from_str(text)
            .map_err(|e| ScenarioError::new("", format!("not valid JSON: {e}")))?;
        Scenario::from_value(&value)
    }

    /// Like [`Scenario::parse`], from an already parsed JSON value.
    pub fn from_value(value: &Value) -> Result<Scenario, ScenarioError> {
        let root = as_object(value, "scenario")?;
        check_keys(
            root,
            "",
            &[
                "name",
                "seed",
                "duration_s",
                "walls",
                "robots",
                "noise",
                "sensors",
                "camera",
            ],
        )?;

        let name = match opt(root, "name") {
            Some(v) => string(v, "name")?,
            None => DEFAULT_NAME.to_string(),
        };
        let seed = match opt(root, "seed") {
            Some(v) => v.as_u64().ok_or_else(|| {
                ScenarioError::new("seed", "expected a whole number from 0 to 2^64-1")
            })?,
            None => DEFAULT_SEED,
        };
        let duration_s = match opt(root, "duration_s") {
            Some(v) => number_in(v, "duration_s", 0.1, MAX_DURATION_S)?,
            None => DEFAULT_DURATION_S,
        };

        let walls = parse_walls(root)?;
        let robots = parse_robots(root)?;
        let noise = parse_noise(root)?;
        let sensors = parse_sensors(root)?;
        let camera = parse_camera(root)?;
        check_distances_held(&robots, &sensors)?;

        Ok(Scenario {
            name,
            seed,
            duration_s,
            walls,
            robots,
            noise,
            sensors,
            camera,
        })
    }

    /// Robots that start inside or touching a wall, or overlapping another
    /// robot. Empty when the scenario can run.
    pub fn placement_problems(&self) -> Vec<ScenarioError> {
        let mut problems = Vec::new();
        let bodies: Vec<ConvexPolygon> = self
            .robots
            .iter()
            .map(|r| P2dx::body(&r.start_pose()))
            .collect();
        for (i, (r, body)) in self.robots.iter().zip(&bodies).enumerate() {
            let (lo, hi) = body.bounds();
            for (j, w) in self.walls.iter().enumerate() {
                let s = w.segment();
                let (wlo, whi) = s.bounds();
                if whi.x < lo.x || wlo.x > hi.x || whi.y < lo.y || wlo.y > hi.y {
                    continue;
                }
                if body.distance_to_segment(&s) <= 1e-9 {
                    problems.push(ScenarioError::new(
                        format!("robots[{i}].start"),
                        format!("robot '{}' starts inside or touching walls[{j}]", r.name),
                    ));
                    break;
                }
            }
            for (k, other) in bodies.iter().enumerate().take(i) {
                if body.touches(other) {
                    problems.push(ScenarioError::new(
                        format!("robots[{i}].start"),
                        format!(
                            "robot '{}' overlaps robot '{}'",
                            r.name, self.robots[k].name
                        ),
                    ));
                }
            }
        }
        problems
    }

    /// The scenario as pretty JSON with every default written out.
    pub fn to_json_pretty(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_else(|_| "{}".to_string())
    }

    /// Axis-aligned bounds of walls and robot starts, as (min, max).
    pub fn bounds(&self) -> (DVec2, DVec2) {
        let mut lo = DVec2::splat(f64::INFINITY);
        let mut hi = DVec2::splat(f64::NEG_INFINITY);
        for w in &self.walls {
            for p in [w.from, w.to] {
                lo = lo.min(DVec2::from(p));
                hi = hi.max(DVec2::from(p));
            }
        }
        for r in &self.robots {
            let p = DVec2::new(r.start[0], r.start[1]);
            lo = lo.min(p - 0.5);
            hi = hi.max(p + 0.5);
        }
        if !lo.is_finite() {
            return (DVec2::ZERO, DVec2::new(10.0, 10.0));
        }
        (lo, hi)
    }
}

/// `walls`: required, at most [`MAX_WALLS`], none of zero length.
fn parse_walls(root: &Map<String, Value>) -> Result<Vec<WallSpec>, ScenarioError> {
    let walls_v = opt(root, "walls").ok_or_else(|| ScenarioError::new("walls", "is required"))?;
    let walls_a = walls_v.as_array().ok_or_else(|| {
        ScenarioError::new(
            "walls",
            format!("expected an array, found {}", type_name(walls_v)),
        )
    })?;
    if walls_a.len() > MAX_WALLS {
        return Err(ScenarioError::new(
            "walls",
            format!("{} walls, at most {MAX_WALLS} allowed", walls_a.len()),
        ));
    }
    let mut walls = Vec::with_capacity(walls_a.len());
    for (i, w) in walls_a.iter().enumerate() {
        let path = format!("walls[{i}]");
        let m = as_object(w, &path)?;
        check_keys(m, &path, &["from", "to", "texture"])?;
        let from = numbers::<2>(
            m.get("from")
                .ok_or_else(|| ScenarioError::new(join(&path, "from"), "is required"))?,
            &join(&path, "from"),
            "[x, y]",
        )?;
        let to = numbers::<2>(
            m.get("to")
                .ok_or_else(|| ScenarioError::new(join(&path, "to"), "is required"))?,
            &join(&path, "to"),
            "[x, y]",
        )?;
        let texture = match m.get("texture") {
            None | Some(Value::Null) => None,
            Some(v) => Some(string(v, &join(&path, "texture"))?),
        };
        let wall = WallSpec { from, to, texture };
        if wall.segment().length() < 1e-6 {
            return Err(ScenarioError::new(
                path,
                "zero-length wall (from equals to)",
            ));
        }
        walls.push(wall);
    }
    Ok(walls)
}

/// `robots`: required, one to [`MAX_ROBOTS`], names unique.
fn parse_robots(root: &Map<String, Value>) -> Result<Vec<RobotSpec>, ScenarioError> {
    let robots_v =
        opt(root, "robots").ok_or_else(|| ScenarioError::new("robots", "is required"))?;
    let robots_a = robots_v.as_array().ok_or_else(|| {
        ScenarioError::new(
            "robots",
            format!("expected an array, found {}", type_name(robots_v)),
        )
    })?;
    if robots_a.is_empty() {
        return Err(ScenarioError::new(
            "robots",
            "at least one robot is required",
        ));
    }
    if robots_a.len() > MAX_ROBOTS {
        return Err(ScenarioError::new(
            "robots",
            format!("{} robots, at most {MAX_ROBOTS} allowed", robots_a.len()),
        ));
    }
    let mut robots: Vec<RobotSpec> = Vec::with_capacity(robots_a.len());
    for (i, r) in robots_a.iter().enumerate() {
        let path = format!("robots[{i}]");
        let m = as_object(r, &path)?;
        check_keys(m, &path, &["name", "start", "follow", "distance", "speed"])?;
        let name_path = join(&path, "name");
        let name = string(
            m.get("name")
                .ok_or_else(|| ScenarioError::new(&name_path, "is required"))?,
            &name_path,
        )?;
        if name.trim().is_empty() {
            return Err(ScenarioError::new(name_path, "must not be empty"));
        }
        if name.chars().count() > 64 {
            return Err(ScenarioError::new(name_path, "longer than 64 characters"));
        }
        if robots.iter().any(|o| o.name == name) {
            return Err(ScenarioError::new(
                name_path,
                format!("duplicate robot name '{name}'"),
            ));
        }
        let start_path = join(&path, "start");
        let start = numbers::<3>(
            m.get("start")
                .ok_or_else(|| ScenarioError::new(&start_path, "is required"))?,
            &start_path,
            "[x, y, theta]",
        )?;
        let follow_path = join(&path, "follow");
        let follow = match m.get("follow") {
            None => return Err(ScenarioError::new(follow_path, "is required")),
            Some(Value::String(s)) if s == "left" => FollowSide::Left,
            Some(Value::String(s)) if s == "right" => FollowSide::Right,
            Some(v) => {
                return Err(ScenarioError::new(
                    follow_path,
                    format!("expected \"left\" or \"right\", found {v}"),
                ))
            }
        };
        let distance = match m.get("distance") {
            Some(v) => number_in(v, &join(&path, "distance"), 0.3, 1.5)?,
            None => DEFAULT_DISTANCE_M,
        };
        let speed = match m.get("speed") {
            Some(v) => number_in(v, &join(&path, "speed"), 0.05, 0.5)?,
            None => DEFAULT_SPEED_MPS,
        };
        robots.push(RobotSpec {
            name,
            start,
            follow,
            distance,
            speed,
        });
    }
    Ok(robots)
}

/// `noise`: optional, each field defaulted on its own.
fn parse_noise(root: &Map<String, Value>) -> Result<NoiseSpec, ScenarioError> {
    let mut noise = NoiseSpec::default();
    if let Some(v) = opt(root, "noise") {
        let m = as_object(v, "noise")?;
        check_keys(
            m,
            "noise",
            &[
                "wheel_slip",
                "wheel_scale_error",
                "wheelbase_error",
                "sonar_std_m",
                "laser_std_m",
            ],
        )?;
        if let Some(v) = m.get("wheel_slip") {
            noise.wheel_slip = number_in(v, "noise.wheel_slip", 0.0, 0.5)?;
        }
        if let Some(v) = m.get("wheel_scale_error") {
            let e = numbers::<2>(v, "noise.wheel_scale_error", "[left, right]")?;
            for (k, x) in e.iter().enumerate() {
                if x.abs() > 0.2 {
                    return Err(ScenarioError::new(
                        format!("noise.wheel_scale_error[{k}]"),
                        format!("{x} is outside [-0.2, 0.2]"),
                    ));
                }
            }
            noise.wheel_scale_error = e;
        }
        if let Some(v) = m.get("wheelbase_error") {
            noise.wheelbase_error = number_in(v, "noise.wheelbase_error", -0.2, 0.2)?;
        }
        if let Some(v) = m.get("sonar_std_m") {
            noise.sonar_std_m = number_in(v, "noise.sonar_std_m", 0.0, 1.0)?;
        }
        if let Some(v) = m.get("laser_std_m") {
            noise.laser_std_m = number_in(v, "noise.laser_std_m", 0.0, 1.0)?;
        }
    }
    Ok(noise)
}

/// `sensors`: optional, each field defaulted on its own.
fn parse_sensors(root: &Map<String, Value>) -> Result<SensorSpec, ScenarioError> {
    let mut sensors = SensorSpec::default();
    if let Some(v) = opt(root, "sensors") {
        let m = as_object(v, "sensors")?;
        check_keys(
            m,
            "sensors",
            &["sonar_range_m", "sonar_cone_deg", "laser_range_m"],
        )?;
        if let Some(v) = m.get("sonar_range_m") {
            sensors.sonar_range_m = number_in(v, "sensors.sonar_range_m", 0.5, 10.0)?;
        }
        if let Some(v) = m.get("sonar_cone_deg") {
            sensors.sonar_cone_deg = number_in(v, "sensors.sonar_cone_deg", 0.0, 60.0)?;
        }
        if let Some(v) = m.get("laser_range_m") {
            sensors.laser_range_m = number_in(v, "sensors.laser_range_m", 0.5, 30.0)?;
        }
    }
    Ok(sensors)
}

/// `camera`: optional, each field defaulted on its own; the camera must sit
/// below the walls' top.
fn parse_camera(root: &Map<String, Value>) -> Result<CameraSpec, ScenarioError> {
    let mut camera = CameraSpec::default();
    if let Some(v) = opt(root, "camera") {
        let m = as_object(v, "camera")?;
        check_keys(
            m,
            "camera",
            &[
                "width",
                "height",
                "hfov_deg",
                "mount_height_m",
                "wall_height_m",
                "pixel_noise_std",
                "exposure_jitter",
                "period_s",
            ],
        )?;
        let whole = |v: &Value, path: &str, lo: u32, hi: u32| -> Result<u32, ScenarioError> {
            let x = number_in(v, path, lo as f64, hi as f64)?;
            if x.fract() != 0.0 {
                return Err(ScenarioError::new(
                    path,
                    format!("{x} is not a whole number of pixels"),
                ));
            }
            Ok(x as u32)
        };
        if let Some(v) = m.get("width") {
            camera.width = whole(v, "camera.width", 16, 640)?;
        }
        if let Some(v) = m.get("height") {
            camera.height = whole(v, "camera.height", 16, 480)?;
        }
        if let Some(v) = m.get("hfov_deg") {
            camera.hfov_deg = number_in(v, "camera.hfov_deg", 20.0, 150.0)?;
        }
        if let Some(v) = m.get("wall_height_m") {
            camera.wall_height_m = number_in(v, "camera.wall_height_m", 0.5, 10.0)?;
        }
        if let Some(v) = m.get("mount_height_m") {
            camera.mount_height_m = number_in(v, "camera.mount_height_m", 0.05, 5.0)?;
        }
        if camera.mount_height_m >= camera.wall_height_m {
            return Err(ScenarioError::new(
                "camera.mount_height_m",
                format!(
                    "{} m is not below the walls' height of {} m",
                    camera.mount_height_m, camera.wall_height_m
                ),
            ));
        }
        if let Some(v) = m.get("pixel_noise_std") {
            camera.pixel_noise_std = number_in(v, "camera.pixel_noise_std", 0.0, 50.0)?;
        }
        if let Some(v) = m.get("exposure_jitter") {
            camera.exposure_jitter = number_in(v, "camera.exposure_jitter", 0.0, 0.5)?;
        }
        if let Some(v) = m.get("period_s") {
            camera.period_s = number_in(v, "camera.period_s", 0.1, 60.0)?;
        }
    }
    Ok(camera)
}

/// Each robot's wall distance must be within its side sonar's reach.
fn check_distances_held(robots: &[RobotSpec], sensors: &SensorSpec) -> Result<(), ScenarioError> {
    for (i, r) in robots.iter().enumerate() {
        if r.distance + 0.2 > sensors.sonar_range_m {
            return Err(ScenarioError::new(
                format!("robots[{i}].distance"),
                format!(
                    "{} m cannot be held: the side sonar only reaches {} m",
                    r.distance, sensors.sonar_range_m
                ),
            ));
        }
    }
    Ok(())
}

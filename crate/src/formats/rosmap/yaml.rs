//! # The map's YAML: what ROS `map_server` reads beside the image
//!
//! A `map_server` map (<http://wiki.ros.org/map_server>, "YAML format") is
//! an image and a small YAML file:
//!
//! ```yaml
//! image: office.pgm          # relative to the YAML's folder (or absolute)
//! resolution: 0.05           # metres per pixel
//! origin: [-10.0, -7.5, 0.0] # pose of the lower-left pixel: x, y, yaw
//! negate: 0                  # 1: white is occupied, black free
//! occupied_thresh: 0.65      # p above this: occupied
//! free_thresh: 0.196         # p below this: free
//! mode: trinary              # optional: trinary (default), scale or raw
//! ```
//!
//! `image`, `resolution` and `origin` are required, as in `map_server`;
//! `negate`, `occupied_thresh` and `free_thresh` default to 0, 0.65 and
//! 0.196 (the values every ROS map tool writes) when absent. Every error
//! names the file and the field. Parsing is by `serde_yaml_ng` into a
//! generic value first, then checked field by field, so "origin: expected
//! [x, y, yaw]" says which field and what was wrong, where a derived
//! struct would only say "invalid type".

use super::MapError;
use serde_yaml_ng::Value;

/// How pixel values become occupancy (`map_server`'s `mode`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Occupied, free or unknown by the two thresholds.
    Trinary,
    /// Between the thresholds, a graded occupancy 1..99 instead of unknown.
    Scale,
    /// The pixel value is the occupancy value itself (0..100, 255 unknown).
    Raw,
}

/// The fields of a map YAML, checked.
#[derive(Clone, Debug, PartialEq)]
pub struct MapYaml {
    /// The image's path as written (relative to the YAML's folder).
    pub image: String,
    pub resolution: f64,
    /// `[x, y, yaw]`: pose of the image's lower-left pixel in the map frame.
    pub origin: [f64; 3],
    pub negate: bool,
    pub occupied_thresh: f64,
    pub free_thresh: f64,
    pub mode: Mode,
}

fn number(v: &Value) -> Option<f64> {
    match v {
        Value::Number(n) => n.as_f64(),
        // `.inf`, `.nan` parse as numbers; a quoted number is a string.
        _ => None,
    }
}

impl MapYaml {
    /// Parses and checks the YAML text of the file called `file`.
    pub fn parse(file: &str, text: &str) -> Result<MapYaml, MapError> {
        let err = |field: &str, msg: String| MapError::new(file, field, msg);
        let doc: Value = serde_yaml_ng::from_str(text)
            .map_err(|e| err("yaml", format!("not valid YAML ({e})")))?;
        let Value::Mapping(map) = &doc else {
            return Err(err(
                "yaml",
                "expected a mapping of fields (image, resolution, origin, ...)".into(),
            ));
        };
        let get = |k: &str| map.get(Value::String(k.into()));
        let image = match get("image") {
            None => {
                return Err(err(
                    "image",
                    "missing (the image file's path is required)".into(),
                ))
            }
            Some(Value::String(s)) if !s.trim().is_empty() => s.clone(),
            Some(_) => return Err(err("image", "expected a file name".into())),
        };
        let resolution = match get("resolution") {
            None => {
                return Err(err(
                    "resolution",
                    "missing (metres per pixel is required)".into(),
                ))
            }
            Some(v) => number(v).ok_or_else(|| err("resolution", "expected a number".into()))?,
        };
        if !resolution.is_finite() || resolution <= 0.0 {
            return Err(err(
                "resolution",
                format!("{resolution} is not a positive finite number of metres per pixel"),
            ));
        }
        let origin = match get("origin") {
            None => return Err(err("origin", "missing ([x, y, yaw] is required)".into())),
            Some(Value::Sequence(s)) if s.len() == 3 => {
                let mut o = [0.0; 3];
                for (k, v) in s.iter().enumerate() {
                    o[k] = number(v).filter(|x| x.is_finite()).ok_or_else(|| {
                        err("origin", format!("element {k} is not a finite number"))
                    })?;
                }
                o
            }
            Some(_) => return Err(err("origin", "expected [x, y, yaw]".into())),
        };
        let negate = match get("negate") {
            None => false,
            Some(Value::Bool(b)) => *b,
            Some(v) => match number(v) {
                Some(0.0) => false,
                Some(1.0) => true,
                _ => return Err(err("negate", "expected 0 or 1".into())),
            },
        };
        let threshold = |key: &str, default: f64| -> Result<f64, MapError> {
            match get(key) {
                None => Ok(default),
                Some(v) => number(v)
                    .filter(|x| x.is_finite() && (0.0..=1.0).contains(x))
                    .ok_or_else(|| err(key, "expected a number from 0 to 1".into())),
            }
        };
        let occupied_thresh = threshold("occupied_thresh", 0.65)?;
        let free_thresh = threshold("free_thresh", 0.196)?;
        if free_thresh > occupied_thresh {
            return Err(err(
                "free_thresh",
                format!("{free_thresh} is above occupied_thresh {occupied_thresh}"),
            ));
        }
        let mode = match get("mode") {
            None => Mode::Trinary,
            Some(Value::String(s)) => match s.as_str() {
                "trinary" => Mode::Trinary,
                "scale" => Mode::Scale,
                "raw" => Mode::Raw,
                other => {
                    return Err(err(
                        "mode",
                        format!("'{other}' is not trinary, scale or raw"),
                    ))
                }
            },
            Some(_) => return Err(err("mode", "expected trinary, scale or raw".into())),
        };
        Ok(MapYaml {
            image,
            resolution,
            origin,
            negate,
            occupied_thresh,
            free_thresh,
            mode,
        })
    }
}

//! # The saved-maps session: what `merge-maps` and "Your maps…" drive
//!
//! Holds the ROS `map_server` maps a user brought (YAML text and image
//! bytes, read by the caller: node from disk, the page from a file picker),
//! merges them ([`crate::merge::saved`]), lets a person refine one pair from
//! a rough overlay, and hands back the report and the merged map as PGM,
//! PNG and YAML. Every error names the file and the field.

use crate::formats::rosmap::{self, write::MergedMap, MapYaml, RosMap};
use crate::geom::Pose2;
use crate::merge::saved::refine::{refine_pair, refuse_if_beaten};
use crate::merge::saved::wallmap::WallMap;
use crate::merge::saved::{merge_all, PairResult, SavedMerge, SavedMergeConfig};
use crate::slam::export::yaml_text;
use glam::DVec2;
use serde::Serialize;

/// The most maps merged at once.
pub const MAX_MAPS: usize = 16;

/// Saved maps and, after [`SavedMaps::merge`], the result.
#[derive(Default)]
pub struct SavedMaps {
    maps: Vec<RosMap>,
    result: Option<SavedMerge>,
    /// The automatic merge's pairs, kept for Refine's check.
    automatic: Vec<PairResult>,
    /// Each group's merged map, made once per result (group 0 is the
    /// first map's: the merged map).
    merged: Vec<Option<MergedMap>>,
}

/// Size, resolution and origin of one map (fields in the order the page
/// has always read them: alphabetical).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MapInfo {
    pub height: usize,
    pub name: String,
    pub origin: [f64; 3],
    pub resolution: f64,
    pub width: usize,
}

/// The `image` field of a map YAML (the path of its image, relative to the
/// YAML's folder), so the caller knows which file to read.
pub fn map_image_path(name: &str, yaml_text: &str) -> Result<String, String> {
    Ok(MapYaml::parse(name, yaml_text)
        .map_err(|e| e.to_string())?
        .image)
}

/// The most cells a map may hold.
pub fn max_cells() -> usize {
    rosmap::MAX_CELLS
}

impl SavedMaps {
    pub fn new() -> SavedMaps {
        SavedMaps::default()
    }

    /// Reads one map (`name`: the YAML's path as given; `image_name`: the
    /// image's path, for messages). Returns its index.
    pub fn add_map(
        &mut self,
        name: &str,
        yaml_text: &str,
        image_name: &str,
        image: &[u8],
    ) -> Result<usize, String> {
        if self.maps.len() >= MAX_MAPS {
            return Err(format!(
                "{name}: at most {MAX_MAPS} maps can be merged at once"
            ));
        }
        let map = rosmap::load(name, yaml_text, image_name, image).map_err(|e| e.to_string())?;
        self.add_loaded(map)
    }

    /// Adds a map already read (a bag's `nav_msgs/OccupancyGrid`, say).
    pub fn add_loaded(&mut self, map: RosMap) -> Result<usize, String> {
        if self.maps.len() >= MAX_MAPS {
            return Err(format!(
                "{}: at most {MAX_MAPS} maps can be merged at once",
                map.name
            ));
        }
        self.maps.push(map);
        self.result = None;
        self.merged.clear();
        Ok(self.maps.len() - 1)
    }

    /// Reads a map in place of map `i` (a file opened again under the same
    /// name, or an image read again at another resolution): the other maps
    /// keep their indices, and the last merge is dropped.
    pub fn replace_map(
        &mut self,
        i: usize,
        name: &str,
        yaml_text: &str,
        image_name: &str,
        image: &[u8],
    ) -> Result<(), String> {
        let n = self.maps.len();
        if i >= n {
            return Err(format!(
                "{name}: there is no map {i} to replace among the {n} opened"
            ));
        }
        let map = rosmap::load(name, yaml_text, image_name, image).map_err(|e| e.to_string())?;
        self.maps[i] = map;
        self.result = None;
        self.merged.clear();
        Ok(())
    }

    fn map(&self, i: usize) -> Result<&RosMap, String> {
        self.maps.get(i).ok_or_else(|| "no such map".to_string())
    }

    /// Size, resolution and origin of map `i`.
    pub fn map_info(&self, i: usize) -> Result<MapInfo, String> {
        let m = self.map(i)?;
        let o = m.origin;
        Ok(MapInfo {
            height: m.height,
            name: m.name.clone(),
            origin: [o.x, o.y, o.theta],
            resolution: m.resolution,
            width: m.width,
        })
    }

    /// Map `i`'s cells as grey values for drawing, top row first (PGM
    /// shades: free 254, occupied 0, unknown 205, `scale` values graded
    /// between).
    pub fn map_pixels(&self, i: usize) -> Result<Vec<u8>, String> {
        let m = self.map(i)?;
        let mut out = Vec::with_capacity(m.data.len());
        for row in m.data.chunks(m.width).rev() {
            out.extend(row.iter().map(|&v| match v {
                0..=100 => (254 - (v as i32 * 254) / 100) as u8,
                _ => 205,
            }));
        }
        Ok(out)
    }

    /// Merges the maps, calling `progress` with a line of text after each
    /// pair; returns the report's `maps` and `merge`.
    pub fn merge(&mut self, progress: &mut dyn FnMut(&str)) -> Result<serde_json::Value, String> {
        if self.maps.len() < 2 {
            return Err("merge-maps needs at least two maps".into());
        }
        let result = merge_all(&self.maps, &SavedMergeConfig::default(), progress);
        let report = result.report(&self.maps);
        self.automatic = result.pairs.clone();
        self.result = Some(result);
        self.merged.clear();
        Ok(report)
    }

    /// Aligns maps `a` and `b` again from a person's rough overlay: map
    /// `b`'s frame at `guess` in map `a`'s frame, as the report's
    /// transforms. The result replaces that pair's verdict and the maps are
    /// joined again, so the report and the merged map follow it. Returns
    /// the pair's result in the report's `pairs[]` format (with `guess`).
    /// The pair is refined in the order the merge judged it, so for `a > b`
    /// it comes back as `b`, `a` with the guess inverted. A refined overlay
    /// is refused when the automatic merge found a different one with 1.5
    /// times its support.
    pub fn refine(
        &mut self,
        a: usize,
        b: usize,
        guess: Pose2,
    ) -> Result<serde_json::Value, String> {
        let n = self.maps.len();
        if a >= n || b >= n || a == b {
            return Err(format!(
                "refine: maps {a} and {b} are not a pair of the {n} maps opened"
            ));
        }
        if !guess.is_finite() {
            return Err(format!(
                "refine: the guess must be finite numbers, got x = {}, y = {}, theta = {}",
                guess.x, guess.y, guess.theta
            ));
        }
        let result = self.result.as_mut().ok_or("refine: merge first")?;
        let automatic = self
            .automatic
            .iter()
            .find(|p| (p.a, p.b) == (a, b) || (p.a, p.b) == (b, a))
            .ok_or("refine: that pair was not judged")?;
        let (a, b, guess) = if automatic.a == a {
            (a, b, guess)
        } else {
            (b, a, guess.inverse())
        };
        let cfg = SavedMergeConfig::default();
        let (ma, mb) = (&self.maps[a], &self.maps[b]);
        let (wa, wb) = (WallMap::new(ma), WallMap::new(mb));
        let mut pair = refine_pair((a, ma, &wa), (b, mb, &wb), guess, &cfg)
            .map_err(|e| format!("refine: {e}"))?;
        refuse_if_beaten(&mut pair, automatic, (ma, mb), &cfg);
        let k = result
            .replace_pair(&self.maps, pair)
            .ok_or("refine: that pair was not judged")?;
        self.merged.clear();
        let report = result.report(&self.maps);
        Ok(report["merge"]["pairs"][k].clone())
    }

    /// Keeps a person's placement of maps `a` and `b` (map `b`'s frame at
    /// `pose` in map `a`'s, as [`SavedMaps::refine`] takes it) as it is,
    /// not verified, after the tests refused it: the maps are joined there
    /// and the report says `verified: false`. Returns the pair's result in
    /// the report's `pairs[]` format (for `a > b` as `b`, `a`).
    pub fn keep_placement(
        &mut self,
        a: usize,
        b: usize,
        pose: Pose2,
    ) -> Result<serde_json::Value, String> {
        let n = self.maps.len();
        if a >= n || b >= n || a == b {
            return Err(format!(
                "keep placement: maps {a} and {b} are not a pair of the {n} maps opened"
            ));
        }
        if !pose.is_finite() {
            return Err(format!(
                "keep placement: the pose must be finite numbers, got x = {}, y = {}, theta = {}",
                pose.x, pose.y, pose.theta
            ));
        }
        let result = self.result.as_mut().ok_or("keep placement: merge first")?;
        let judged = result
            .pairs
            .iter()
            .find(|p| (p.a, p.b) == (a, b) || (p.a, p.b) == (b, a))
            .ok_or("keep placement: that pair was not judged")?;
        let (a, b, pose) = if judged.a == a {
            (a, b, pose)
        } else {
            (b, a, pose.inverse())
        };
        let refused = if judged.guess.is_some() && judged.verified {
            judged.reason.clone()
        } else {
            String::new()
        };
        let k = result
            .keep_placement(&self.maps, (a, b), pose, &refused)
            .ok_or("keep placement: that pair was not judged")?;
        self.merged.clear();
        let report = result.report(&self.maps);
        Ok(report["merge"]["pairs"][k].clone())
    }

    /// The report's `maps` and `merge`, as [`SavedMaps::merge`] returned
    /// it, after any [`SavedMaps::refine`].
    pub fn report(&self) -> Result<serde_json::Value, String> {
        let r = self.result.as_ref().ok_or("merge first")?;
        Ok(r.report(&self.maps))
    }

    /// Group `group`'s merged map: its maps joined in the frame of its
    /// first map, made once per result. Group 0 is the first map's, whose
    /// frame is the merged frame.
    fn merged(&mut self, group: usize) -> Result<&MergedMap, String> {
        let r = self.result.as_ref().ok_or("merge first")?;
        let g = r.groups.get(group).ok_or_else(|| {
            format!(
                "there is no group {} of maps: the merge found {}",
                group + 1,
                r.groups.len()
            )
        })?;
        if self.merged.len() != r.groups.len() {
            self.merged = vec![None; r.groups.len()];
        }
        if self.merged[group].is_none() {
            let joined: Vec<(&RosMap, Pose2)> = g
                .poses
                .iter()
                .zip(&self.maps)
                .filter_map(|(p, m)| p.map(|p| (m, p)))
                .collect();
            self.merged[group] =
                Some(rosmap::write::merge_maps(&joined).map_err(|e| e.to_string())?);
        }
        self.merged[group]
            .as_ref()
            .ok_or_else(|| "no merged map".into())
    }

    /// The merged map (the first map's group) as a binary PGM.
    pub fn merged_pgm(&mut self) -> Result<Vec<u8>, String> {
        self.group_pgm(0)
    }

    /// The same pixels as a PNG.
    pub fn merged_png(&mut self) -> Result<Vec<u8>, String> {
        self.group_png(0)
    }

    /// The map_server YAML naming `image`.
    pub fn merged_yaml(&mut self, image: &str) -> Result<String, String> {
        self.group_yaml(0, image)
    }

    /// Group `group`'s merged map as a binary PGM (its first map's frame).
    pub fn group_pgm(&mut self, group: usize) -> Result<Vec<u8>, String> {
        Ok(self.merged(group)?.pgm())
    }

    /// Group `group`'s merged map as a PNG.
    pub fn group_png(&mut self, group: usize) -> Result<Vec<u8>, String> {
        self.merged(group)?.png().map_err(|e| e.to_string())
    }

    /// Group `group`'s map_server YAML naming `image`, its origin rounded
    /// to the micrometre (the sums that place the maps leave float noise:
    /// `1.2000000000000002`).
    pub fn group_yaml(&mut self, group: usize, image: &str) -> Result<String, String> {
        let m = self.merged(group)?;
        let tidy = |v: f64| (v * 1e6).round() / 1e6 + 0.0;
        let origin = DVec2::new(tidy(m.origin.x), tidy(m.origin.y));
        Ok(yaml_text(image, m.resolution, origin))
    }
}

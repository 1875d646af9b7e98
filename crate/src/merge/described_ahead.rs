//! # Frames described elsewhere: the merge's SURF work, done ahead on other threads
//!
//! Describing the robots' frames (rendering each stored frame, then SURF)
//! is most of a merge's work, and each frame's features depend on nothing
//! but the frame and the SURF settings. A stored frame is its pose, the
//! other robots' bodies at that instant and its noise seed
//! ([`crate::camera::capture`]); its pixels are a function of those and of
//! the static world, which the scenario fixes. So a *second* lab of the same
//! scenario — in a node worker or a Web Worker, each with its own wasm
//! instance — renders the same picture and finds the same features, bit for
//! bit, and can do so while this lab is still simulating.
//!
//! The host runs that schedule; this module gives it the pieces:
//!
//! 1. [`frames_to_describe`]: which frames a merge with a given method will
//!    describe (the same choice [`super::job::MergeJob::new`] makes), so the
//!    host can hand them out as soon as they are captured. The automatic
//!    method's choice, thinning by place, only ever adds frames as the run
//!    goes on; a frame chosen early and dropped later costs work, not
//!    correctness.
//! 2. One frame's parts, as JSON (the session's `FrameSpec`, in
//!    `crate::lab::frame_spec`, since they hold the camera's true pose), for
//!    the other lab, which describes it and sends back the features packed
//!    in a flat `f32` array ([`encode`]). The work splits in two halves as
//!    well: the other lab may only render the frame and send its grey bytes
//!    back, for this lab to describe ([`describe_image`]). Rendering is the half that needs the
//!    wall textures, which a lab paints on first use; a lab that has painted
//!    them renders fast, and SURF needs nothing painted at all.
//! 3. [`DescribedFrames`]: where this lab keeps what came back ([`decode`]),
//!    keyed by robot and frame index and tied to the SURF settings they were
//!    made with. A merge started afterwards takes the features it finds
//!    there and describes the rest itself, so the report is the same however
//!    many threads helped, or none.

use super::config::MergeConfig;
use super::frames::{frame_infos, frames_taking_part, strongest_features};
use crate::camera::CameraImage;
use crate::sim::Simulation;
use crate::surf::{Descriptor, Features, GrayImage, Keypoint, SurfConfig};
use std::collections::HashMap;

/// Numbers per keypoint in [`encode`]'s array: x, y, scale, orientation,
/// laplacian sign, response, then the 64 descriptor values.
pub const PACKED_LEN: usize = 6 + 64;

/// The frames (robot, frame index) a merge with `config` describes, in
/// robot and capture order. While a robot's mapping is away on another
/// thread, only among the frames it has reported a SLAM pose for (a frame
/// chosen by its odometry pose would mostly be one the merge does not ask
/// for).
pub fn frames_to_describe(sim: &Simulation, config: &MergeConfig) -> Vec<(usize, usize)> {
    (0..sim.robots.len())
        .flat_map(|r| {
            let mut infos = frame_infos(sim, r);
            let known = sim.robots[r].slam_estimates().len();
            infos.retain(|f| f.step < known);
            frames_taking_part(&infos, config)
                .into_iter()
                .map(move |k| (r, infos[k].index))
                .collect::<Vec<_>>()
        })
        .collect()
}

/// The features a merge with `config` finds in a rendered frame (none in
/// an image too small for SURF).
pub fn describe_image(img: CameraImage, config: &MergeConfig) -> Features {
    match GrayImage::new(img.width as usize, img.height as usize, img.gray) {
        Ok(img) => strongest_features(&img, &config.surf, config.max_keypoints),
        Err(_) => Features::default(),
    }
}

/// Features packed for the boundary: `[count, then PACKED_LEN numbers per
/// keypoint]`. Every field is an `f32` already (the sign as ±1), so the
/// round trip through [`decode`] is exact.
pub fn encode(f: &Features) -> Vec<f32> {
    let mut out = Vec::with_capacity(1 + f.len() * PACKED_LEN);
    out.push(f.len() as f32);
    for (k, d) in f.keypoints.iter().zip(&f.descriptors) {
        out.extend_from_slice(&[
            k.x,
            k.y,
            k.scale,
            k.orientation,
            k.laplacian as f32,
            k.response,
        ]);
        out.extend_from_slice(&d.0);
    }
    out
}

/// The features [`encode`] packed; an error names what is wrong with a
/// malformed array.
pub fn decode(data: &[f32]) -> Result<Features, String> {
    let (&count, rest) = data.split_first().ok_or("packed features: empty array")?;
    if !(count >= 0.0 && count.fract() == 0.0) || rest.len() != count as usize * PACKED_LEN {
        return Err(format!(
            "packed features: {} numbers after a count of {count}, expected {} per keypoint",
            rest.len(),
            PACKED_LEN
        ));
    }
    if let Some(bad) = rest.iter().find(|v| !v.is_finite()) {
        return Err(format!("packed features: {bad} is not a finite number"));
    }
    let mut f = Features::default();
    for p in rest.chunks_exact(PACKED_LEN) {
        let laplacian = match p[4] {
            1.0 => 1,
            -1.0 => -1,
            other => return Err(format!("packed features: laplacian sign {other}")),
        };
        f.keypoints.push(Keypoint {
            x: p[0],
            y: p[1],
            scale: p[2],
            orientation: p[3],
            laplacian,
            response: p[5],
        });
        let mut d = [0f32; 64];
        d.copy_from_slice(&p[6..]);
        f.descriptors.push(Descriptor(d));
    }
    Ok(f)
}

/// Features of frames described ahead of a merge, for one SURF setting.
#[derive(Clone, Debug, Default)]
pub struct DescribedFrames {
    settings: Option<(SurfConfig, usize)>,
    features: HashMap<(usize, usize), Features>,
}

impl DescribedFrames {
    fn settings_of(config: &MergeConfig) -> (SurfConfig, usize) {
        (config.surf, config.max_keypoints)
    }

    /// Keeps the features of frame `index` of robot `robot`, made with
    /// `config`'s SURF settings (features made with other settings are
    /// dropped: a merge could not use both).
    pub fn insert(&mut self, config: &MergeConfig, robot: usize, index: usize, f: Features) {
        let settings = Self::settings_of(config);
        if self.settings != Some(settings) {
            self.features.clear();
            self.settings = Some(settings);
        }
        self.features.insert((robot, index), f);
    }

    /// Whether frame `index` of robot `robot` is described for `config`.
    pub fn contains(&self, config: &MergeConfig, robot: usize, index: usize) -> bool {
        self.settings == Some(Self::settings_of(config))
            && self.features.contains_key(&(robot, index))
    }

    /// Takes the features of frame `index` of robot `robot`, if they were
    /// made with `config`'s settings.
    pub fn take(&mut self, config: &MergeConfig, robot: usize, index: usize) -> Option<Features> {
        if self.settings != Some(Self::settings_of(config)) {
            return None;
        }
        self.features.remove(&(robot, index))
    }

    /// Keeps only the frames `(robot, index)` for which `keep` says so.
    pub fn retain(&mut self, mut keep: impl FnMut(usize, usize) -> bool) {
        self.features
            .retain(|&(robot, index), _| keep(robot, index));
    }

    pub fn len(&self) -> usize {
        self.features.len()
    }

    /// Heap bytes of the features kept (keypoints and descriptors).
    pub fn memory_bytes(&self) -> usize {
        self.features
            .values()
            .map(|f| {
                f.keypoints.capacity() * std::mem::size_of::<Keypoint>()
                    + f.descriptors.capacity() * std::mem::size_of::<Descriptor>()
            })
            .sum()
    }

    pub fn is_empty(&self) -> bool {
        self.features.is_empty()
    }
}

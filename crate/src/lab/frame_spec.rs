//! # A stored frame, for another lab to render and describe
//!
//! The session's half of [`crate::merge::described_ahead`]: a stored frame's
//! parts ([`FrameSpec`]) as JSON, for a lab of the same scenario on another
//! thread, which renders the same pixels ([`render_spec`]) and may describe
//! them as the merge would ([`describe_spec`]). A frame's parts include the
//! camera's true pose (a camera images the real world), so they live in the
//! session layer, the only one that reads the truth; nothing of it reaches
//! the merge but the pixels.

use crate::camera::{CameraImage, RobotBox};
use crate::geom::Pose2;
use crate::merge::config::MergeConfig;
use crate::merge::described_ahead::describe_image;
use crate::sim::Simulation;
use crate::surf::Features;
use glam::DVec2;
use serde::{Deserialize, Serialize};

/// Another robot's body as a frame shows it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BodySpec {
    pub corners: Vec<[f64; 2]>,
    pub rgb: [u8; 3],
}

/// One stored frame's parts: enough for a lab of the same scenario to
/// render it exactly. The truth pose is the simulator's (a camera images the
/// real world); nothing of it reaches the merge but the pixels.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FrameSpec {
    pub robot: usize,
    pub index: usize,
    pub truth: [f64; 3],
    pub others: Vec<BodySpec>,
    pub noise_seed: u64,
}

impl FrameSpec {
    /// Frame `index` of robot `robot` of `sim`.
    pub fn of(sim: &Simulation, robot: usize, index: usize) -> Result<FrameSpec, String> {
        let r = sim
            .robots
            .get(robot)
            .ok_or_else(|| format!("no robot {robot}"))?;
        let f = r
            .frames
            .frames
            .iter()
            .find(|f| f.index == index)
            .ok_or_else(|| format!("robot {robot} has no frame {index}"))?;
        Ok(FrameSpec {
            robot,
            index,
            truth: [f.truth.x, f.truth.y, f.truth.theta],
            others: f
                .others
                .iter()
                .map(|b| BodySpec {
                    corners: b.corners.iter().map(|c| [c.x, c.y]).collect(),
                    rgb: b.rgb,
                })
                .collect(),
            noise_seed: f.noise_seed,
        })
    }
}

/// The features of the frame `spec` describes, rendered by `sim` (a
/// simulation of the same scenario, at any time of its run).
pub fn describe_spec(sim: &Simulation, spec: &FrameSpec, config: &MergeConfig) -> Features {
    describe_image(render_spec(sim, spec), config)
}

/// The picture of the frame `spec` describes, rendered by `sim` (a
/// simulation of the same scenario): exactly the frame's own pixels.
pub fn render_spec(sim: &Simulation, spec: &FrameSpec) -> CameraImage {
    let others: Vec<RobotBox> = spec
        .others
        .iter()
        .map(|b| RobotBox {
            corners: b.corners.iter().map(|c| DVec2::new(c[0], c[1])).collect(),
            rgb: b.rgb,
        })
        .collect();
    let truth = Pose2::new(spec.truth[0], spec.truth[1], spec.truth[2]);
    sim.render_stored(&truth, &others, spec.noise_seed)
}

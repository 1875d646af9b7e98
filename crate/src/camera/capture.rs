//! # Frame capture, as Fraps did in the thesis
//!
//! In the thesis, Fraps saved the camera view once a second (§6.1.2) and
//! MATLAB kept the time, pose, sonar and laser of every step (§6.2.1); the
//! two were joined by time. Here a frame is captured every
//! `camera.period_s` simulated seconds (1 s by default, starting at t = 0)
//! together with the odometry pose, sonar and laser of that instant, and the
//! true pose beside it for scoring.
//!
//! A frame is stored as what it takes to *render* it — the true pose, the
//! other robots' bodies in view, and the seed of its pixel noise — not as
//! pixels. The world is static, so rendering it later gives exactly the
//! picture the camera took, while a run keeps a few hundred bytes per frame
//! instead of 75 kB, and pays for rendering only the frames that are looked
//! at: the merge describes perhaps half of them (the automatic method's
//! place thinning) or a tenth (the thesis's squareness test), and the page
//! shows one at a time. [`crate::sim::Simulation::frame_image`] renders one.
//!
//! Memory is still bounded by a budget shared by all robots
//! ([`FRAME_BUDGET_BYTES`]), for runs of days. When a robot's share is full
//! the store is **thinned**: every other frame is dropped and the capture
//! period doubles, so the frames kept still span the whole run evenly. The
//! number of frames dropped is reported.
//!
//! A stored frame is small, but the features a merge describes in it are
//! not: up to [`FEATURE_BYTES`] (160 SURF keypoints with their 64-number
//! descriptors), a hundred times the frame. Measured on 16 robots × 900 s
//! (`crate/examples/memory.rs`), the merge's features were 378 MB of a
//! 923 MB peak, while the stores held 28 MB. So the budget charges each
//! frame what it may cost with its features ([`FRAME_BYTES`]): it bounds
//! what the merge will hold, whatever the number of robots and the length
//! of the run. The default keeps every frame of four robots for half an
//! hour, of sixteen for nine minutes; beyond, each robot's frames still
//! span its whole run, sparser.

use crate::camera::RobotBox;
use crate::geom::Pose2;
use crate::sensors::{LASER_BEAMS, SONAR_COUNT};

/// Frames of all robots together, with the features a merge may describe
/// in them, use at most this much memory (384 MiB: about 8,800 frames, 37 minutes
/// of frames at one a second for four robots).
pub const FRAME_BUDGET_BYTES: usize = 384 << 20;

/// The most a merge keeps of one described frame: its strongest 160 SURF
/// keypoints (`merge::config::MergeConfig::max_keypoints`), each 24 bytes
/// with a 64-number descriptor of 256 (checked in `tests/merge_described.rs`).
pub const FEATURE_BYTES: usize = 160 * (24 + 256);

/// What one stored frame may cost, roughly: its senses plus two robot
/// bodies, and the features a merge may describe in it.
pub const FRAME_BYTES: usize =
    std::mem::size_of::<CapturedFrame>() + 2 * (4 * 16 + 32) + FEATURE_BYTES;

/// One captured frame and the robot's senses at that instant.
#[derive(Clone, Debug, PartialEq)]
pub struct CapturedFrame {
    /// Capture number for this robot (0, 1, 2, … in capture order; frames
    /// dropped by thinning leave gaps).
    pub index: usize,
    pub step: usize,
    pub time_s: f64,
    /// What the robot believed (odometry frame).
    pub odometry: Pose2,
    /// Where it really was (world frame). For scoring only.
    pub truth: Pose2,
    pub sonar_m: [f32; SONAR_COUNT],
    /// Laser ranges in mm; `u16::MAX` for no return.
    pub laser_mm: [u16; LASER_BEAMS],
    /// Image size (px).
    pub width: u32,
    pub height: u32,
    /// The other robots' bodies at that instant, as the camera sees them.
    pub others: Vec<RobotBox>,
    /// Seed of the frame's pixel noise and exposure jitter, drawn from the
    /// robot's camera stream at capture.
    pub noise_seed: u64,
}

/// One robot's frames, within its share of the budget.
#[derive(Clone, Debug)]
pub struct FrameStore {
    pub frames: Vec<CapturedFrame>,
    /// Capture every this many control steps.
    pub period_steps: usize,
    pub max_frames: usize,
    /// Frames dropped by thinning.
    pub dropped: usize,
    next_index: usize,
}

impl FrameStore {
    /// A store for frames of `frame_bytes` each (see [`FRAME_BYTES`]), with
    /// `robots` robots sharing the budget, capturing every `period_steps`
    /// steps.
    pub fn new(frame_bytes: usize, robots: usize, period_steps: usize) -> Self {
        let mut store = FrameStore {
            frames: Vec::new(),
            period_steps: period_steps.max(1),
            max_frames: 2,
            dropped: 0,
            next_index: 0,
        };
        store.set_budget(FRAME_BUDGET_BYTES, frame_bytes, robots);
        store
    }

    /// Gives the store its share of a budget of `budget_bytes` for all
    /// `robots` robots' frames of `frame_bytes` each (at least two frames).
    /// A store already fuller than its new share thins at its next frame.
    pub fn set_budget(&mut self, budget_bytes: usize, frame_bytes: usize, robots: usize) {
        let share = budget_bytes / robots.max(1);
        self.max_frames = (share / frame_bytes.max(1)).max(2);
    }

    /// Whether frame `index` is stored (captured and not thinned since).
    pub fn holds(&self, index: usize) -> bool {
        self.frames
            .binary_search_by_key(&index, |f| f.index)
            .is_ok()
    }

    /// Whether frame `index` was captured and then dropped by thinning.
    pub fn thinned(&self, index: usize) -> bool {
        index < self.next_index && !self.holds(index)
    }

    /// Whether a frame is due at `step`.
    pub fn due(&self, step: usize) -> bool {
        step.is_multiple_of(self.period_steps)
    }

    /// The index the next frame will get.
    pub fn next_index(&self) -> usize {
        self.next_index
    }

    /// Stores a frame, thinning first if the share is full.
    pub fn push(&mut self, mut frame: CapturedFrame) {
        if self.frames.len() >= self.max_frames {
            let before = self.frames.len();
            let mut k = 0;
            self.frames.retain(|_| {
                k += 1;
                k % 2 == 1
            });
            self.dropped += before - self.frames.len();
            self.period_steps *= 2;
        }
        frame.index = self.next_index;
        self.next_index += 1;
        self.frames.push(frame);
    }

    /// Memory the stored frames take (bytes, roughly).
    pub fn bytes(&self) -> usize {
        self.frames
            .iter()
            .map(|f| {
                std::mem::size_of::<CapturedFrame>()
                    + f.others
                        .iter()
                        .map(|b| std::mem::size_of::<RobotBox>() + 16 * b.corners.len())
                        .sum::<usize>()
            })
            .sum()
    }
}

//! # slamlab: a multi-robot SLAM and vision-based map-merging lab
//!
//! This crate is the pure-Rust core of a browser lab that follows H. Li,
//! *Multi-robot SLAM and Map Merging* (Auburn University, 2015). Two or more
//! Pioneer P2DX-like robots wall-follow a maze, each with wheel odometry,
//! eight sonars, a 180° laser and a camera. Every module here is plain Rust,
//! testable natively with `cargo test`; the only module that knows about
//! JavaScript is [`bindings`], a thin wasm-bindgen layer over [`lab::Lab`].
//!
//! The folder list reads like the pipeline, bottom layer first:
//!
//! | module | what it is |
//! |---|---|
//! | [`geom`] | poses, segments and exact ray casting |
//! | [`rng`] | the seeded random numbers every noisy thing draws from |
//! | [`palette`] | robot colours, wall hint colours, name hashes |
//! | [`kinematics`] | differential-drive motion of a P2DX |
//! | [`world`] | the walls robots live among, with a spatial index |
//! | [`maze`] | random mazes for exercises and benchmarks |
//! | [`scenario`] | the scenario file: walls, robots, noise; validation |
//! | [`sensors`] | the sonar ring and the laser range finder |
//! | [`odometry`] | wheel encoders with slip and bias: what the robot believes |
//! | [`follower`] | the thesis's wall-following controller |
//! | [`camera`] | the pinhole camera, wall textures, frame capture |
//! | [`surf`] | SURF features, matching and MSAC (Bay et al. 2008) |
//! | [`slam`] | per-robot occupancy grids, scan matching, map scoring and export |
//! | [`sim`] | the fixed-step simulation and its per-robot logs |
//! | [`render`] | tiny-skia drawing of the world, robots and sensors |
//! | [`formats`] | robots' files read into the lab's types: CARMEN logs, ROS maps |
//! | [`merge`] | map merging: the thesis's method, the automatic one, a map-only baseline |
//! | [`lab`] | the session the page and the CLI drive, its views and the report |
//! | [`bindings`] | the wasm-bindgen boundary |
//!
//! One rule orders them: `bindings → lab → {merge, render} → sim → {slam,
//! camera, surf, follower, odometry} → … → geom`. A module imports only
//! modules of the layers below it; nothing below [`lab`] imports it, and
//! only [`lab`] reads the ground truth (to score and to show it).
//! `tests/layers.rs` checks the rule (ARCHITECTURE.md, "Layers").
//!
//! Conventions everywhere: metres, radians, seconds; world frame x right,
//! y up, θ counter-clockwise from +x. Only the renderer flips y.

pub mod bindings;
pub mod camera;
pub mod follower;
pub mod formats;
pub mod geom;
pub mod kinematics;
pub mod lab;
pub mod maze;
pub mod merge;
pub mod odometry;
pub mod palette;
pub mod render;
pub mod rng;
pub mod scenario;
pub mod sensors;
pub mod sim;
pub mod slam;
pub mod surf;
pub mod world;

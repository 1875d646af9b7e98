//! # slamlab: a multi-robot SLAM and vision-based map-merging lab
//!
//! This crate is the pure-Rust core of a browser lab that follows H. Li,
//! *Multi-robot SLAM and Map Merging* (Auburn University, 2015). Two or more
//! Pioneer P2DX-like robots wall-follow a maze, each with wheel odometry,
//! eight sonars, a 180° laser and a camera. Every module here is plain Rust,
//! testable natively with `cargo test`; the only module that knows about
//! JavaScript is [`bindings`], a thin wasm-bindgen layer over [`lab::Lab`].
//!
//! The folder list reads like the pipeline:
//!
//! | module | what it is |
//! |---|---|
//! | [`geom`] | poses, segments and exact ray casting |
//! | [`rng`] | the seeded random numbers every noisy thing draws from |
//! | [`scenario`] | the scenario file: walls, robots, noise; validation |
//! | [`world`] | the walls robots live among, with a spatial index |
//! | [`kinematics`] | differential-drive motion of a P2DX |
//! | [`odometry`] | wheel encoders with slip and bias: what the robot believes |
//! | [`sensors`] | the sonar ring and the laser range finder |
//! | [`carmen`] | reading CARMEN laser logs (real data: FLASER, ROBOTLASER1, ODOM) |
//! | [`camera`] | the pinhole camera, wall textures, frame capture |
//! | [`follower`] | the thesis's wall-following controller |
//! | [`sim`] | the fixed-step simulation and its per-robot logs |
//! | [`slam`] | per-robot occupancy grids, scan matching, map scoring and export |
//! | [`render`] | tiny-skia drawing of the world, robots and sensors |
//! | [`report`] | the JSON report of a run (`web/cli.mjs run --json`) |
//! | [`surf`] | SURF features, matching and MSAC (Bay et al. 2008) |
//! | [`lab`] | the session object the page and the CLI drive |
//!
//! Conventions everywhere: metres, radians, seconds; world frame x right,
//! y up, θ counter-clockwise from +x. Only the renderer flips y.

pub mod bindings;
pub mod camera;
pub mod carmen;
pub mod follower;
pub mod geom;
pub mod kinematics;
pub mod lab;
pub mod maze;
pub mod merge;
pub mod odometry;
pub mod render;
pub mod report;
pub mod rng;
pub mod scenario;
pub mod sensors;
pub mod sim;
pub mod slam;
pub mod surf;
pub mod world;

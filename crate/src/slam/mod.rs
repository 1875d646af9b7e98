//! # SLAM: each robot maps in its own frame, and scan matching beats drift
//!
//! The thesis (Chapter 4) defines SLAM as recovering the path `X_T` and the
//! map `M` from odometry `U_T` and observations `Z_T`, then maps at raw
//! odometry poses; its Chapter 7 names the resulting noise as the first
//! problem left open. This module does both, side by side, per robot:
//!
//! | stage | file | follows |
//! |---|---|---|
//! | log-odds occupancy grid, beam model, growth | [`grid`] | Thrun et al., *Probabilistic Robotics* §9.2 |
//! | smoothed map for matching | [`likelihood`] | Olson 2009 §III-B; Hector SLAM §IV-A |
//! | multi-resolution correlative search | [`correlative`] | Olson, ICRA 2009 |
//! | Gauss–Newton on the smoothed map (map merging) | [`gauss_newton`] | Kohlbrecher et al., SSRR 2011 |
//! | Gauss–Newton of scan points onto mapped surfaces | [`surface`] | Chen & Medioni 1992 (point-to-plane) |
//! | the surface layer, kept by blocks where hits are | [`surface_blocks`] | Museth 2013 (OpenVDB leaf blocks) |
//! | corridor degeneracy guard | [`degeneracy`] | Zhang, Kaess, Singh, ICRA 2016 |
//! | pose filter with odometry self-calibration | [`filter`] | Thrun et al. §7.4; Martinelli 2007 |
//! | the two mappers, online | [`mapper`] | thesis §4.3 (online SLAM) |
//! | drawing and ROS map export | [`export`] | ROS `map_server` format |
//! | tables of scans for real lasers | [`multires`] | Olson, ICRA 2009 |
//! | a match's covariance from its response | [`match_covariance`] | Olson, ICRA 2009 §IV-C; Konolige et al. 2010 |
//! | point-to-line ICP on points, off the raster's grain | [`icp`] | Besl & McKay 1992; Chen & Medioni 1992 |
//! | pose graph, sparse least squares | [`posegraph`] | Lu & Milios 1997; Grisetti et al. 2010 |
//! | loop closure by correlative matching | [`loop_closure`] | Konolige et al. 2010; Hess et al. 2016 |
//! | SLAM for recorded laser logs | [`logs`] | Karto / slam_toolbox, Cartographer |
//! | its square walls' heading prior | [`manhattan`] | Nguyen et al., IROS 2006 (Orthogonal SLAM) |
//! | the simulated robots' loop-closing back end | [`robot_graph`] | Konolige et al. 2010; Hess et al. 2016 |
//! | its key edges' compounded covariance | [`key_chain`] | Smith, Self, Cheeseman 1990; Konolige et al. 2010 |
//! | scoring: ATE, map figures, relation errors | [`eval`] | Sturm et al. 2012; Kümmerle et al. 2009 |
//! | a robot's mapping handed to another thread and back | [`handoff`] | — |
//!
//! The simulation feeds every robot's [`RobotMapping`] once per step with
//! the odometry pose and the laser scan (never the truth).

pub mod correlative;
pub mod degeneracy;
pub mod eval;
pub mod export;
pub mod filter;
pub mod gauss_newton;
pub mod grid;
pub mod handoff;
pub mod icp;
pub mod keep_capacity;
pub mod key_chain;
pub mod likelihood;
pub mod logs;
pub mod loop_closure;
pub mod manhattan;
pub mod mapper;
pub mod match_covariance;
pub mod multires;
pub mod posegraph;
pub mod robot_graph;
#[cfg(test)]
mod scenes;
pub mod surface;
pub mod surface_blocks;

pub use grid::{CellState, GridConfig, OccupancyGrid};
pub use mapper::{MapperKind, MatchStatus, RobotMapping, SlamConfig};

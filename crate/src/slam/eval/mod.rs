//! # Scoring SLAM against a reference
//!
//! Read only where results are scored (the session, tests, examples):
//! never by an estimator.
//!
//! | measure | file | follows |
//! |---|---|---|
//! | trajectory and map error against the simulator's truth | [`scoring`] | Sturm et al., IROS 2012 (ATE) |
//! | relation errors against a reference's relations | [`relations`] | Kümmerle et al., Auton. Robots 2009 |
//! | relations the scans themselves fix | [`verified`] | Kümmerle et al., Auton. Robots 2009 |
//! | the benchmark's hand-checked relation files | [`benchmark_relations`] | Kümmerle et al., Auton. Robots 2009 |
//! | those relations checked against their own scans and wheels | [`relation_check`] | Kümmerle et al., Auton. Robots 2009 |

pub mod benchmark_relations;
pub mod relation_check;
pub mod relations;
pub mod scoring;
pub mod verified;

//! # A robot's mapping on another thread: both halves of the hand-off
//!
//! The command line spreads sixteen robots' SLAM over the machine's cores
//! (`web/cli/slam-pool.mjs`). The lab's half ([`Lab::send_mapping_away`]
//! and the methods after it) sends a robot's mapping away as bytes, then
//! its steps in batches, and takes it home at the end; the other thread's
//! half ([`MappingAway`]) maps those steps exactly as the lab would have
//! (the bytes and the reason it is exact: [`crate::slam::handoff`]).

use super::Lab;
use crate::slam::handoff::{mapping_from_bytes, mapping_to_bytes, observe_packed};
use crate::slam::RobotMapping;

impl Lab {
    /// Hands robot `robot`'s mapping to another thread
    /// ([`crate::sim::Simulation::send_mapping_away`]): its bytes, for a
    /// [`crate::slam::handoff`] reader there. Starts the run if none is.
    pub fn send_mapping_away(&mut self, robot: usize) -> Result<Vec<u8>, String> {
        let sim = self.start().map_err(|e| e.to_string())?;
        sim.send_mapping_away(robot)
    }

    /// The steps robot `robot`'s mapping, away, has yet to be sent (packed).
    pub fn take_mapping_steps(&mut self, robot: usize) -> Vec<u8> {
        self.sim
            .as_mut()
            .map(|s| s.take_mapping_steps(robot))
            .unwrap_or_default()
    }

    /// Appends the estimates robot `robot`'s mapping, away, reports
    /// ([`crate::sim::Simulation::note_away_estimates`]).
    pub fn note_away_estimates(&mut self, robot: usize, flat: &[f64]) -> Result<(), String> {
        let sim = self.sim.as_mut().ok_or("nothing has run yet")?;
        sim.note_away_estimates(robot, flat)
    }

    /// Takes robot `robot`'s mapping back from another thread
    /// ([`crate::sim::Simulation::bring_mapping_home`]).
    pub fn bring_mapping_home(&mut self, robot: usize, bytes: &[u8]) -> Result<(), String> {
        let sim = self.sim.as_mut().ok_or("nothing has run yet")?;
        sim.bring_mapping_home(robot, bytes)
    }
}

/// A robot's mapping on another thread: made from
/// [`Lab::send_mapping_away`]'s bytes, fed [`Lab::take_mapping_steps`]'s
/// batches in order, and sent home as bytes for [`Lab::bring_mapping_home`].
pub struct MappingAway {
    mapping: RobotMapping,
}

impl MappingAway {
    pub fn new(bytes: &[u8]) -> Result<MappingAway, String> {
        Ok(MappingAway {
            mapping: mapping_from_bytes(bytes)?,
        })
    }

    /// Maps a batch of steps; returns how many it held. A batch cut short
    /// is an error and maps none of its steps.
    pub fn observe(&mut self, steps: &[u8]) -> Result<usize, String> {
        observe_packed(&mut self.mapping, steps)
    }

    /// Steps mapped so far (the run's, from its start).
    pub fn steps(&self) -> usize {
        self.mapping.estimates().len().saturating_sub(1)
    }

    /// The estimates from row `row` on (row 0 is the start), flat
    /// `[x, y, theta, …]`, for [`Lab::note_away_estimates`].
    pub fn estimates_from(&self, row: usize) -> Vec<f64> {
        let e = self.mapping.estimates();
        e.get(row..)
            .unwrap_or_default()
            .iter()
            .flat_map(|p| [p.x, p.y, p.theta])
            .collect()
    }

    /// The mapping as bytes, for [`Lab::bring_mapping_home`].
    pub fn finish(&self) -> Result<Vec<u8>, String> {
        mapping_to_bytes(&self.mapping)
    }
}

//! # A robot's mapping handed to another thread, and back
//!
//! A robot's [`RobotMapping`] reads nothing but its own odometry pose and
//! laser scan, once per step (see [`RobotMapping::observe`]), and nothing
//! of the run reads the mapping back while the robots drive: the follower
//! steers by its sensors, and a frame's SLAM pose is read when a merge
//! chooses its frames. So a run may hand a robot's mapping to another
//! thread, send it the robot's steps as they come, and take the mapping
//! back at the end, and it has run exactly as it would have at home: the
//! same code on the same numbers in the same order, so the same bits.
//! The command line does this to spread sixteen robots' SLAM over the
//! machine's cores (`web/cli/slam-pool.mjs`).
//!
//! Three things cross between the threads, each as bytes:
//! - the mapping itself ([`mapping_to_bytes`], [`mapping_from_bytes`]):
//!   serde's derive of every part of it, written by `postcard` (compact,
//!   and exact: an `f64` goes as its eight bytes);
//! - a batch of steps ([`pack_step`], [`observe_packed`]): per step the
//!   beam count, the odometry pose, the laser's maximum range, every range
//!   as its eight bytes and one byte of flags per beam (no return,
//!   reflective) — the scan exactly as the mapper would have read it;
//! - nothing else: the thread that maps needs no world, no scenario, no
//!   truth.

use super::RobotMapping;
use crate::geom::Pose2;
use crate::sensors::LaserScan;

/// Flag bit of a beam that met nothing in range.
const NO_RETURN: u8 = 1;
/// Flag bit of a bright return.
const REFLECTIVE: u8 = 2;

/// The mapping as bytes, exactly ([`mapping_from_bytes`] reads them).
pub fn mapping_to_bytes(mapping: &RobotMapping) -> Result<Vec<u8>, String> {
    postcard::to_allocvec(mapping).map_err(|e| format!("cannot write a robot's mapping: {e}"))
}

/// The mapping [`mapping_to_bytes`] wrote.
pub fn mapping_from_bytes(bytes: &[u8]) -> Result<RobotMapping, String> {
    postcard::from_bytes(bytes).map_err(|e| format!("not a robot's mapping ({e})"))
}

/// Appends one step (the odometry pose and the scan taken there) to `out`.
pub fn pack_step(odometry: &Pose2, scan: &LaserScan, out: &mut Vec<u8>) {
    let beams = scan.ranges_m.len();
    out.reserve(4 + 8 * (4 + beams) + beams);
    out.extend_from_slice(&(beams as u32).to_le_bytes());
    for v in [odometry.x, odometry.y, odometry.theta, scan.range_max_m] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    for r in &scan.ranges_m {
        out.extend_from_slice(&r.to_le_bytes());
    }
    for i in 0..beams {
        let no_return = scan.max_range.get(i).copied().unwrap_or(false);
        let bright = scan.reflective.get(i).copied().unwrap_or(false);
        out.push((u8::from(no_return) * NO_RETURN) | (u8::from(bright) * REFLECTIVE));
    }
}

/// Reads a batch of steps [`pack_step`] wrote into `mapping`, in order.
/// Returns how many steps it held; a batch cut short is an error, and then
/// no step of it has been observed.
pub fn observe_packed(mapping: &mut RobotMapping, bytes: &[u8]) -> Result<usize, String> {
    let steps = unpack_steps(bytes)?;
    for (odometry, scan) in &steps {
        mapping.observe(odometry, scan);
    }
    Ok(steps.len())
}

/// The steps of a batch, all read before any is used.
fn unpack_steps(bytes: &[u8]) -> Result<Vec<(Pose2, LaserScan)>, String> {
    let mut steps = Vec::new();
    let mut at = 0;
    while at < bytes.len() {
        let cut = || format!("a batch of steps is cut short in step {}", steps.len());
        let take = |at: &mut usize, n: usize| -> Result<&[u8], String> {
            let s = bytes.get(*at..*at + n).ok_or_else(cut)?;
            *at += n;
            Ok(s)
        };
        let beams = u32::from_le_bytes(take(&mut at, 4)?.try_into().map_err(|_| cut())?) as usize;
        if beams > 100_000 {
            return Err(format!("a step claims {beams} beams"));
        }
        let mut f64s = take(&mut at, 8 * (4 + beams))?
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap_or([0; 8])));
        let mut next = || f64s.next().unwrap_or(f64::NAN);
        let odometry = Pose2::new(next(), next(), next());
        let range_max_m = next();
        let ranges_m: Vec<f64> = (0..beams).map(|_| next()).collect();
        let flags = take(&mut at, beams)?;
        steps.push((
            odometry,
            LaserScan {
                ranges_m,
                max_range: flags.iter().map(|f| f & NO_RETURN != 0).collect(),
                reflective: flags.iter().map(|f| f & REFLECTIVE != 0).collect(),
                range_max_m,
            },
        ));
    }
    Ok(steps)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sensors::laser::LASER_BEAMS;

    /// A room 6 × 4 m seen from `pose`, cast by hand: the distance along
    /// each beam to the first of the four walls.
    fn room_scan(pose: &Pose2) -> LaserScan {
        let (range_max_m, mut ranges_m, mut max_range) = (4.0, Vec::new(), Vec::new());
        for i in 0..LASER_BEAMS {
            let a = pose.theta + crate::sensors::laser::beam_bearing(i);
            let (c, s) = (a.cos(), a.sin());
            let mut d = f64::INFINITY;
            for (n, wall) in [
                (c, 6.0 - pose.x),
                (-c, pose.x),
                (s, 4.0 - pose.y),
                (-s, pose.y),
            ] {
                if n > 1e-9 {
                    d = d.min(wall / n);
                }
            }
            max_range.push(d > range_max_m);
            ranges_m.push(d.min(range_max_m));
        }
        let reflective = (0..LASER_BEAMS).map(|i| i % 17 == 0).collect();
        LaserScan {
            ranges_m,
            max_range,
            reflective,
            range_max_m,
        }
    }

    fn steps() -> Vec<(Pose2, LaserScan)> {
        (0..60)
            .map(|k| {
                let t = k as f64 * 0.1;
                let truth = Pose2::new(1.0 + 0.6 * t, 2.0 + 0.2 * (t * 0.7).sin(), 0.1 * t);
                let odometry = Pose2::new(truth.x - 1.0, truth.y - 2.0, truth.theta * 1.01);
                (odometry, room_scan(&truth))
            })
            .collect()
    }

    #[test]
    fn a_mapping_handed_off_midway_ends_bit_for_bit_as_one_that_stayed() {
        let steps = steps();
        let mut home = RobotMapping::default();
        for (o, s) in &steps {
            home.observe(o, s);
        }
        // Away after 20 steps: the mapping and then two batches cross as bytes.
        let mut away = RobotMapping::default();
        for (o, s) in &steps[..20] {
            away.observe(o, s);
        }
        let mut away = mapping_from_bytes(&mapping_to_bytes(&away).unwrap()).unwrap();
        for batch in steps[20..].chunks(25) {
            let mut bytes = Vec::new();
            for (o, s) in batch {
                pack_step(o, s, &mut bytes);
            }
            assert_eq!(observe_packed(&mut away, &bytes).unwrap(), batch.len());
        }
        let back = mapping_from_bytes(&mapping_to_bytes(&away).unwrap()).unwrap();
        assert_eq!(back.estimates().len(), 61);
        assert_eq!(back.estimates(), home.estimates());
        assert_eq!(
            mapping_to_bytes(&back).unwrap(),
            mapping_to_bytes(&home).unwrap()
        );
        assert_eq!(back.counts, home.counts);
        // What the lab counts as their memory too (capacities, kept).
        assert_eq!(back.slam_map.memory_bytes(), home.slam_map.memory_bytes());
        assert_eq!(
            back.odometry_map.memory_bytes(),
            home.odometry_map.memory_bytes()
        );
        let (g_back, g_home) = (back.graph.as_ref().unwrap(), home.graph.as_ref().unwrap());
        assert!(
            g_home.graph.nodes.len() > 1,
            "the test drives far enough for keys"
        );
        assert_eq!(g_back.memory_bytes(), g_home.memory_bytes());
    }

    #[test]
    fn a_batch_cut_short_is_refused_whole() {
        let steps = steps();
        let mut bytes = Vec::new();
        for (o, s) in &steps[..3] {
            pack_step(o, s, &mut bytes);
        }
        let mut m = RobotMapping::default();
        let err = observe_packed(&mut m, &bytes[..bytes.len() - 5]).unwrap_err();
        assert!(err.contains("cut short in step 2"), "{err}");
        assert_eq!(m.estimates().len(), 1, "no step observed");
        assert!(mapping_from_bytes(&[1, 2, 3]).is_err());
    }
}

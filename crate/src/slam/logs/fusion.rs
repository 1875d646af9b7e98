//! # Fusing the smoothed scans with the odometry
//!
//! The smoothing of [`super::logslam`] (step 7) places every scan by
//! point-to-line ICP on the keys around it. Each placement is a measurement
//! of where the scan was, with an error of its own; the wheel odometry
//! between two neighbouring scans is a second, independent measurement of
//! how far apart they were. Over a few scans good wheels can be more
//! precise than any one match (a scan of few, far walls), and over many
//! scans they drift while the matches do not. A fixed-lag smoother weighs
//! the two: it minimises, over every scan's pose `x_i`,
//!
//! ```text
//!   Σ_i ‖x_i − x̂_i‖²_{Λ_i}  +  Σ_i ρ(‖(x_i⁻¹ ⊕ x_{i+1}) ⊖ z_i‖²_{Q⁻¹})
//! ```
//!
//! with `x̂_i` the ICP placement, `Λ_i` its information (the point-to-line
//! normal equations, so a corridor's match is loose along the corridor and
//! the odometry carries the scan there), `z_i` the odometry's step and `ρ`
//! Huber's kernel (a wheel slip, or odometry that stalls and then jumps,
//! is an outlier rather than a step to follow). Each pose is linked only
//! to its neighbours, so each Gauss–Newton step is a block-tridiagonal
//! system, solved in one sweep forwards and one back (the block Thomas
//! algorithm): linear in the number of scans.
//!
//! **How much to trust each** is measured from the log itself, because
//! wheels differ from robot to robot (the raw ACES odometry is good over a
//! metre; MIT CSAIL's stalls and jumps). The difference between the ICP
//! placements' relative pose over `k` scans and the odometry's over the
//! same `k` scans has a variance of `k·q + c`: the odometry's error is a
//! random walk (`q` a step), the placements' error is the same at any lag
//! (`c`, twice one placement's variance). Fitting that line to the robust
//! variances (the median absolute deviation) at lags 1, 2, 4, 8 and 16
//! gives both noises, per axis, without any setting per log — the
//! idea of the Allan variance used to characterise inertial sensors.
//! The ICP information matrices keep their shape and are scaled so that
//! their median variance is the measured one.
//!
//! **Only the odometry's position is fused, not its heading.** A wheel's
//! heading error is not a random walk of equal steps: it comes in the
//! turns, where the wheels slip, and there it exceeds what the line fit
//! says, while a scan measures heading against the walls directly. On the
//! raw ACES log, fusing the heading too made the relations' rotation error
//! worse (0.343° against 0.305° without it) for the same translation
//! error (`tests/bench/relations_native.sh`).
//!
//! Where the placements are already better than the odometry at every lag
//! (the fitted placement noise at its floor, as on the raw MIT CSAIL log,
//! whose odometry stalls and jumps), the odometry's weight is negligible
//! and the fusion leaves the placements as they are.

use crate::geom::{wrap_angle, Pose2};
use crate::slam::filter::{inverse3, mul, transpose};

/// One scan's ICP placement and the information of its normal equations
/// (point-to-line, unit weights; world-frame `[x, y, θ]`).
#[derive(Clone, Copy, Debug)]
pub struct Placement {
    pub pose: Pose2,
    pub information: [[f64; 3]; 3],
}

/// The noises measured from a log: the odometry's per step and one
/// placement's, each `[along x, along y, heading]` (robot frame; m², rad²).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct FusionNoise {
    pub odometry_step: [f64; 3],
    pub placement: [f64; 3],
}

/// Lags the noises are measured at (scans apart).
const LAGS: [usize; 5] = [1, 2, 4, 8, 16];

/// Huber's threshold on an odometry step's normalised residual.
const ODOMETRY_HUBER: f64 = 3.0;

/// Gauss–Newton steps of the fusion.
const STEPS: usize = 4;

/// Variance floor (m², rad²): no measurement is trusted below it.
const FLOOR: [f64; 3] = [1e-6, 1e-6, 1e-8];

/// The relative pose `a⁻¹ ⊕ b` as `[x, y, θ]`.
fn relative(a: &Pose2, b: &Pose2) -> [f64; 3] {
    let r = a.between(b);
    [r.x, r.y, r.theta]
}

/// The variance of `values` from their median absolute deviation.
fn robust_variance(values: &mut [f64]) -> Option<f64> {
    if values.len() < 20 {
        return None;
    }
    let median = median_of(values);
    let mut dev: Vec<f64> = values.iter().map(|v| (v - median).abs()).collect();
    let mad = median_of(&mut dev);
    Some((1.4826 * mad).powi(2))
}

/// The median of `values` (the upper one of an even count; reorders them).
fn median_of(values: &mut [f64]) -> f64 {
    let mid = values.len() / 2;
    *values.select_nth_unstable_by(mid, f64::total_cmp).1
}

/// Measures the odometry's and the placements' noise (module doc); `None`
/// when too few scans have a placement to tell.
pub fn measure_noise(placements: &[Option<Placement>], odometry: &[Pose2]) -> Option<FusionNoise> {
    let mut lines = Vec::new();
    for &k in &LAGS {
        let mut diffs: [Vec<f64>; 3] = Default::default();
        for i in 0..placements.len().saturating_sub(k) {
            let (Some(a), Some(b)) = (&placements[i], &placements[i + k]) else {
                continue;
            };
            let m = relative(&a.pose, &b.pose);
            let o = relative(&odometry[i], &odometry[i + k]);
            diffs[0].push(m[0] - o[0]);
            diffs[1].push(m[1] - o[1]);
            diffs[2].push(wrap_angle(m[2] - o[2]));
        }
        let mut v = [0.0; 3];
        for (axis, d) in diffs.iter_mut().enumerate() {
            v[axis] = robust_variance(d)?;
        }
        lines.push((k as f64, v));
    }
    // Least squares of v = k·q + c on each axis.
    let n = lines.len() as f64;
    let mk = lines.iter().map(|l| l.0).sum::<f64>() / n;
    let skk: f64 = lines.iter().map(|l| (l.0 - mk).powi(2)).sum();
    let mut noise = FusionNoise {
        odometry_step: [0.0; 3],
        placement: [0.0; 3],
    };
    for (axis, floor) in FLOOR.iter().enumerate() {
        let mv = lines.iter().map(|l| l.1[axis]).sum::<f64>() / n;
        let skv: f64 = lines.iter().map(|l| (l.0 - mk) * (l.1[axis] - mv)).sum();
        let q = (skv / skk).max(*floor);
        let c = (mv - q * mk).max(2.0 * floor);
        noise.odometry_step[axis] = q;
        noise.placement[axis] = c / 2.0;
    }
    Some(noise)
}

type M3 = [[f64; 3]; 3];

fn add(a: &mut M3, b: &M3) {
    for r in 0..3 {
        for c in 0..3 {
            a[r][c] += b[r][c];
        }
    }
}

fn mul_vec(a: &M3, v: &[f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|r| (0..3).map(|k| a[r][k] * v[k]).sum())
}

/// The placements' information scaled to the measured noise: the
/// translational block so that its median variance (mean of the two axes)
/// is the measured one, the heading likewise.
fn scaled_information(placements: &[Option<Placement>], noise: &FusionNoise) -> Vec<Option<M3>> {
    let covariances: Vec<Option<M3>> = placements
        .iter()
        .map(|p| p.as_ref().and_then(|p| inverse3(&p.information)))
        .collect();
    let mut t: Vec<f64> = covariances
        .iter()
        .flatten()
        .map(|c| (c[0][0] + c[1][1]) / 2.0)
        .collect();
    let mut r: Vec<f64> = covariances.iter().flatten().map(|c| c[2][2]).collect();
    if t.is_empty() {
        return vec![None; placements.len()];
    }
    let (mt, mr) = (median_of(&mut t), median_of(&mut r));
    let st = (noise.placement[0] + noise.placement[1]) / 2.0;
    let d = [
        (mt / st).sqrt(),
        (mt / st).sqrt(),
        (mr / noise.placement[2]).sqrt(),
    ];
    placements
        .iter()
        .map(|p| {
            let p = p.as_ref()?;
            let mut m = p.information;
            for (r, row) in m.iter_mut().enumerate() {
                for (c, v) in row.iter_mut().enumerate() {
                    *v *= d[r] * d[c];
                }
            }
            Some(m)
        })
        .collect()
}

/// Fuses the placements with the odometry (module doc), starting from
/// `poses` (one per scan; a scan without a placement is held only by the
/// odometry to its neighbours and, weakly, by its pose). Returns the fused
/// poses.
pub fn fuse(
    poses: &[Pose2],
    placements: &[Option<Placement>],
    odometry: &[Pose2],
    noise: &FusionNoise,
) -> Vec<Pose2> {
    let n = poses.len();
    let information = scaled_information(placements, noise);
    // A scan without a placement keeps a loose hold on its pose: a
    // hundredth of a placement's information.
    let loose = [0, 1, 2].map(|a| 0.01 / noise.placement[a]);
    // The odometry's step in position only: its heading is not fused
    // (module doc).
    let omega = [
        1.0 / noise.odometry_step[0],
        1.0 / noise.odometry_step[1],
        0.0,
    ];
    let mut x: Vec<Pose2> = poses.to_vec();
    for _ in 0..STEPS {
        let mut diag = vec![[[0.0; 3]; 3]; n];
        let mut upper = vec![[[0.0; 3]; 3]; n];
        let mut b = vec![[0.0; 3]; n];
        for i in 0..n {
            let (target, info) = match (&placements[i], &information[i]) {
                (Some(p), Some(m)) => (p.pose, *m),
                _ => (
                    poses[i],
                    [
                        [loose[0], 0.0, 0.0],
                        [0.0, loose[1], 0.0],
                        [0.0, 0.0, loose[2]],
                    ],
                ),
            };
            let e = [
                x[i].x - target.x,
                x[i].y - target.y,
                wrap_angle(x[i].theta - target.theta),
            ];
            add(&mut diag[i], &info);
            let g = mul_vec(&info, &e);
            for a in 0..3 {
                b[i][a] -= g[a];
            }
        }
        for i in 0..n.saturating_sub(1) {
            let (a, c) = (x[i], x[i + 1]);
            let z = relative(&odometry[i], &odometry[i + 1]);
            let r = relative(&a, &c);
            let e = [r[0] - z[0], r[1] - z[1], wrap_angle(r[2] - z[2])];
            let norm = (0..3).map(|k| e[k] * e[k] * omega[k]).sum::<f64>().sqrt();
            let w = if norm <= ODOMETRY_HUBER {
                1.0
            } else {
                ODOMETRY_HUBER / norm
            };
            let (s, co) = a.theta.sin_cos();
            let (dx, dy) = (c.x - a.x, c.y - a.y);
            let ji: M3 = [
                [-co, -s, -s * dx + co * dy],
                [s, -co, -co * dx - s * dy],
                [0.0, 0.0, -1.0],
            ];
            let jj: M3 = [[co, s, 0.0], [-s, co, 0.0], [0.0, 0.0, 1.0]];
            let om: M3 = [
                [w * omega[0], 0.0, 0.0],
                [0.0, w * omega[1], 0.0],
                [0.0, 0.0, w * omega[2]],
            ];
            let jit_om = mul(&transpose(&ji), &om);
            let jjt_om = mul(&transpose(&jj), &om);
            add(&mut diag[i], &mul(&jit_om, &ji));
            add(&mut diag[i + 1], &mul(&jjt_om, &jj));
            upper[i] = mul(&jit_om, &jj);
            let gi = mul_vec(&jit_om, &e);
            let gj = mul_vec(&jjt_om, &e);
            for k in 0..3 {
                b[i][k] -= gi[k];
                b[i + 1][k] -= gj[k];
            }
        }
        let Some(delta) = solve_block_tridiagonal(diag, &upper, b) else {
            break;
        };
        for (p, d) in x.iter_mut().zip(&delta) {
            *p = Pose2::new(p.x + d[0], p.y + d[1], wrap_angle(p.theta + d[2]));
        }
    }
    x
}

/// Solves the symmetric block-tridiagonal system with diagonal blocks
/// `diag`, blocks `upper[i]` linking `i` to `i + 1` (and their transposes
/// below), right side `b`: the block Thomas algorithm.
fn solve_block_tridiagonal(
    mut diag: Vec<M3>,
    upper: &[M3],
    mut b: Vec<[f64; 3]>,
) -> Option<Vec<[f64; 3]>> {
    let n = diag.len();
    let mut inv = Vec::with_capacity(n);
    for i in 0..n {
        if i > 0 {
            // Eliminate the block below the diagonal of row i.
            let l = mul(&transpose(&upper[i - 1]), &inv[i - 1]);
            let lu = mul(&l, &upper[i - 1]);
            let lb = mul_vec(&l, &b[i - 1]);
            for r in 0..3 {
                b[i][r] -= lb[r];
                for c in 0..3 {
                    diag[i][r][c] -= lu[r][c];
                }
            }
        }
        inv.push(inverse3(&diag[i])?);
    }
    let mut x = vec![[0.0; 3]; n];
    for i in (0..n).rev() {
        let mut rhs = b[i];
        if i + 1 < n {
            let u = mul_vec(&upper[i], &x[i + 1]);
            for r in 0..3 {
                rhs[r] -= u[r];
            }
        }
        x[i] = mul_vec(&inv[i], &rhs);
    }
    Some(x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    /// A winding path of `n` scans 5 cm apart, its odometry (a random walk
    /// of `odo_sd` m per step, heading exact) and ICP placements (white
    /// noise of `place_sd` m, information for that noise).
    fn scene(
        n: usize,
        odo_sd: f64,
        place_sd: f64,
        seed: u64,
    ) -> (Vec<Pose2>, Vec<Pose2>, Vec<Option<Placement>>) {
        let mut rng = Rng::new(seed);
        let mut truth = vec![Pose2::new(0.0, 0.0, 0.0)];
        for i in 1..n {
            let turn = 0.02 * ((i as f64) / 50.0).sin();
            truth.push(truth[i - 1].compose(&Pose2::new(0.05, 0.0, turn)));
        }
        let mut odometry = vec![truth[0]];
        for i in 1..n {
            let step = truth[i - 1].between(&truth[i]);
            let noisy = Pose2::new(
                step.x + odo_sd * rng.gaussian(),
                step.y + odo_sd * rng.gaussian(),
                step.theta,
            );
            odometry.push(odometry[i - 1].compose(&noisy));
        }
        let info = 1.0 / (place_sd * place_sd);
        let placements = truth
            .iter()
            .map(|t| {
                Some(Placement {
                    pose: Pose2::new(
                        t.x + place_sd * rng.gaussian(),
                        t.y + place_sd * rng.gaussian(),
                        t.theta + 0.001 * rng.gaussian(),
                    ),
                    information: [[info, 0.0, 0.0], [0.0, info, 0.0], [0.0, 0.0, 1e6]],
                })
            })
            .collect();
        (truth, odometry, placements)
    }

    fn rms(a: &[Pose2], b: &[Pose2]) -> f64 {
        (a.iter()
            .zip(b)
            .map(|(p, q)| p.position().distance_squared(q.position()))
            .sum::<f64>()
            / a.len() as f64)
            .sqrt()
    }

    #[test]
    fn measures_both_noises_from_their_growth_with_the_lag() {
        let (_, odometry, placements) = scene(4000, 0.002, 0.01, 7);
        let noise = measure_noise(&placements, &odometry).unwrap();
        for axis in 0..2 {
            let odo = noise.odometry_step[axis].sqrt();
            let place = noise.placement[axis].sqrt();
            assert!(
                (odo - 0.002).abs() < 0.0006,
                "odometry σ {odo} against 0.002"
            );
            assert!(
                (place - 0.01).abs() < 0.002,
                "placement σ {place} against 0.01"
            );
        }
    }

    #[test]
    fn fused_poses_are_nearer_the_truth_than_either_measurement() {
        let (truth, odometry, placements) = scene(2000, 0.002, 0.01, 3);
        let placed: Vec<Pose2> = placements.iter().map(|p| p.unwrap().pose).collect();
        let noise = measure_noise(&placements, &odometry).unwrap();
        let fused = fuse(&placed, &placements, &odometry, &noise);
        let (before, after) = (rms(&placed, &truth), rms(&fused, &truth));
        // Two measurements of similar worth over a few steps: the fused
        // error is well under the placements' (≈ 1 cm).
        assert!(
            after < 0.6 * before,
            "fused {after} m, placements {before} m"
        );
    }

    #[test]
    fn a_wheel_slip_is_not_followed() {
        let (truth, mut odometry, placements) = scene(600, 0.001, 0.01, 5);
        // The odometry jumps 0.5 m sideways at scan 300 and stays there.
        for p in odometry.iter_mut().skip(300) {
            *p = Pose2::new(p.x, p.y + 0.5, p.theta);
        }
        let placed: Vec<Pose2> = placements.iter().map(|p| p.unwrap().pose).collect();
        let noise = measure_noise(&placements, &odometry).unwrap();
        let fused = fuse(&placed, &placements, &odometry, &noise);
        let worst = fused
            .iter()
            .zip(&truth)
            .map(|(p, t)| p.position().distance(t.position()))
            .fold(0.0, f64::max);
        assert!(worst < 0.05, "a scan moved {worst} m by the slip");
        assert!(rms(&fused, &truth) < rms(&placed, &truth));
    }

    #[test]
    fn the_block_tridiagonal_solve_matches_a_dense_one() {
        // Three blocks: a 9 × 9 symmetric positive-definite system.
        let mut rng = Rng::new(11);
        let mut upper = [[0.0; 9]; 9];
        for (r, row) in upper.iter_mut().enumerate() {
            for (c, v) in row.iter_mut().enumerate() {
                if c > r && (r / 3).abs_diff(c / 3) <= 1 {
                    *v = rng.range(-1.0, 1.0);
                }
            }
        }
        // Symmetric and diagonally dominant.
        let dense: [[f64; 9]; 9] = std::array::from_fn(|r| {
            std::array::from_fn(|c| match r.cmp(&c) {
                std::cmp::Ordering::Equal => 10.0,
                std::cmp::Ordering::Less => upper[r][c],
                std::cmp::Ordering::Greater => upper[c][r],
            })
        });
        let b: Vec<[f64; 3]> = (0..3).map(|i| [i as f64, 1.0, -2.0]).collect();
        let block = |i: usize, j: usize| -> M3 {
            [0, 1, 2].map(|r| [0, 1, 2].map(|c| dense[3 * i + r][3 * j + c]))
        };
        let x = solve_block_tridiagonal(
            vec![block(0, 0), block(1, 1), block(2, 2)],
            &[block(0, 1), block(1, 2)],
            b.clone(),
        )
        .unwrap();
        for r in 0..9 {
            let ax: f64 = (0..9).map(|c| dense[r][c] * x[c / 3][c % 3]).sum();
            assert!((ax - b[r / 3][r % 3]).abs() < 1e-12, "row {r}: {ax}");
        }
    }
}

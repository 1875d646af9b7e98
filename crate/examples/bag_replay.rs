//! Replays a ROS bag (a file or a rosbag2 folder) or a CARMEN log through
//! the log SLAM as `run-log` does, and prints what was picked, the
//! replay's counts, its time and, with a ground truth, the ATE; with
//! `--poses`, every scan's final pose at full precision (to diff two
//! formats of one log).
//!
//! `cargo run --release -p slamlab --example bag_replay -- BAG_OR_LOG [--poses] [--png MAP.png]
//!  [--odom-none] [--odom-topic T] [--scan-topic T] [--truth-topic T] [--relations FILE [--check-relations]]
//!  [--json REPORT.json]`
//!
//! `--check-relations`: each relation of the file checked
//! against its two scans ([`slamlab::slam::eval::verified::check_pair`]):
//! scan `t2` aligned onto scan `t1` by point-to-line ICP from the
//! relation and from the replay's relative pose. Where both reach one pose
//! that pins every direction, that pose is the scans' own relation; a
//! relation more than 0.1 m or 1° from it, at which the scans fit worse
//! (by 2 mm of mean misfit), is contradicted by its own scans. Where the
//! scans settle no pose (a corridor), a relation over at most 16 scans is
//! checked against the wheel odometry instead
//! ([`slamlab::slam::eval::verified::odometry_contradicts`]). Prints the
//! counts; where the scans settle a pose, how far the relations and the
//! replay each lie from it (the relation file's own noise beside ours);
//! the replay's error against the relations contradicted by neither; and
//! each contradicted relation.
//! (settings to measure: `SLAMLAB_LOG_SLAM=key=value,...`)

#[path = "../../tests/real_support/mod.rs"]
mod support;

use slamlab::lab::bag_file::{BagFile, Picks};
use slamlab::lab::log_replay::LogReplay;
use std::path::Path;
use std::time::Instant;

fn read_bag(path: &Path) -> Result<BagFile, String> {
    let name = path.display().to_string();
    let mut bag = BagFile::new(&name);
    let mut files: Vec<std::path::PathBuf> = Vec::new();
    if path.is_dir() {
        let meta = path.join("metadata.yaml");
        if meta.exists() {
            let yaml = std::fs::read_to_string(&meta).map_err(|e| e.to_string())?;
            bag.set_metadata(&yaml)?;
            files = bag.metadata_files().iter().map(|f| path.join(f)).collect();
        }
        if files.is_empty() {
            let mut found: Vec<_> = std::fs::read_dir(path)
                .map_err(|e| e.to_string())?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().is_some_and(|x| x == "db3" || x == "mcap"))
                .collect();
            found.sort();
            files = found;
        }
    } else {
        files.push(path.to_path_buf());
    }
    for f in files {
        let bytes = std::fs::read(&f).map_err(|e| format!("{}: {e}", f.display()))?;
        bag.begin_file(&f.display().to_string())?;
        for piece in bytes.chunks(8 << 20) {
            bag.push(piece)?;
        }
        bag.end_file()?;
    }
    bag.finish()?;
    Ok(bag)
}

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let path = Path::new(
        args.first()
            .ok_or("usage: bag_replay BAG_OR_LOG [--poses] [--odom-none]")?,
    );
    let poses = args.iter().any(|a| a == "--poses");
    let t0 = Instant::now();
    let mut replay = if path.is_dir() || {
        let head = std::fs::read(path).map_err(|e| e.to_string())?;
        !slamlab::lab::bag_file::bag_kind(&head[..head.len().min(16)]).is_empty()
    } {
        let bag = read_bag(path)?;
        let info = bag.info();
        eprintln!(
            "{}: {} messages, {} topics, read in {:.3} s",
            info.container,
            info.messages,
            info.topics.len(),
            t0.elapsed().as_secs_f64()
        );
        let after = |flag: &str| {
            args.iter()
                .position(|a| a == flag)
                .and_then(|i| args.get(i + 1).cloned())
        };
        let picks = Picks {
            odom_none: args.iter().any(|a| a == "--odom-none"),
            odom_topic: after("--odom-topic"),
            truth_topic: after("--truth-topic"),
            truth_none: args.iter().any(|a| a == "--truth-none"),
            scan_topic: after("--scan-topic"),
        };
        bag.replay(&picks)?
    } else {
        LogReplay::new(&std::fs::read(path).map_err(|e| e.to_string())?)
            .map_err(|e| e.to_string())?
    };
    // Settings to measure: SLAMLAB_LOG_SLAM="key=value,..." as for the
    // other log examples.
    replay.configure(|c| *c = support::config_from_env())?;
    // --half first|second: that half of the scans on its own.
    if let Some(i) = args.iter().position(|a| a == "--half") {
        let n = replay.laser_records();
        match args.get(i + 1).map(String::as_str) {
            Some("first") => replay.set_range(0, Some(n / 2 - 1))?,
            Some("second") => replay.set_range(n / 2, None)?,
            _ => return Err("--half first|second".into()),
        }
    }
    if let Some(i) = args.iter().position(|a| a == "--relations") {
        let file = args.get(i + 1).ok_or("--relations FILE")?;
        replay.set_relations(&std::fs::read_to_string(file).map_err(|e| e.to_string())?)?;
    }
    let t1 = Instant::now();
    replay.finish()?;
    let report = replay.report(serde_json::Value::Null)?;
    if let Some(p) = replay.picked() {
        eprintln!(
            "picked: {}",
            serde_json::to_string(p).map_err(|e| e.to_string())?
        );
    }
    eprintln!(
        "{} scans, {} keys, {} closures, replayed in {:.2} s; map {} x {}",
        report.scans.len(),
        report.slam.keys,
        report.loop_closures.len(),
        t1.elapsed().as_secs_f64(),
        report.map.width,
        report.map.height
    );
    eprintln!(
        "stats: {}",
        serde_json::to_string(&report.slam).map_err(|e| e.to_string())?
    );
    if let Some(q) = &report.relations {
        // Local relations (the two scans under 5 s apart) and revisits
        // (over 60 s apart) apart: the front end's precision and the
        // loops' consistency.
        let part = |keep: &dyn Fn(f64) -> bool| {
            let e: Vec<_> = q.errors.iter().filter(|e| keep(e.t2 - e.t1)).collect();
            let n = e.len().max(1) as f64;
            (e.len(), e.iter().map(|e| e.trans_m).sum::<f64>() / n)
        };
        let (nl, local) = part(&|dt| dt < 5.0);
        let (nr, revisit) = part(&|dt| dt > 60.0);
        eprintln!("relations by gap: {nl} local {local:.4} m, {nr} revisits {revisit:.4} m");
        eprintln!(
            "relations: {} of {} matched; translation {:.4} ± {:.4} m (max {:.3}), rotation {:.3} ± {:.3} deg (max {:.2})",
            q.matched, q.count, q.trans_m.mean, q.trans_m.sd, q.trans_m.max, q.rot_deg.mean, q.rot_deg.sd, q.rot_deg.max
        );
    }
    if args.iter().any(|a| a == "--check-relations") {
        print_check(&replay)?;
    }
    if let Some(a) = report.ate_m {
        eprintln!(
            "ATE against the ground truth: {a:.4} m over {} scans",
            report.ate_scans.unwrap_or(0)
        );
    }
    if let Some(i) = args.iter().position(|a| a == "--png") {
        let out = args.get(i + 1).ok_or("--png FILE")?;
        std::fs::write(out, replay.map_png()?).map_err(|e| e.to_string())?;
    }
    if let Some(i) = args.iter().position(|a| a == "--json") {
        let out = args.get(i + 1).ok_or("--json FILE")?;
        std::fs::write(
            out,
            serde_json::to_string(&report).map_err(|e| e.to_string())?,
        )
        .map_err(|e| e.to_string())?;
    }
    if poses {
        for s in &report.scans {
            println!("{} {:?} {:?}", s.index, s.time, s.pose);
        }
    }
    Ok(())
}

/// `--check-relations` (module doc): prints the replay's
/// [`LogReplay::relation_check`].
fn print_check(replay: &LogReplay) -> Result<(), String> {
    let c = replay.relation_check().ok_or("no relations to check")?;
    eprintln!(
        "checked against their scans: {} relations, {} settled by the scans, {} contradicted by them",
        c.checked, c.settled, c.by_scans
    );
    eprintln!(
        "against the pose the scans settle: the relations err {:.4} m / {:.3} deg, ours {:.4} m / {:.3} deg",
        c.relations_vs_scans.trans_m,
        c.relations_vs_scans.rot_deg,
        c.ours_vs_scans.trans_m,
        c.ours_vs_scans.rot_deg
    );
    eprintln!(
        "where the scans settle no pose, {} relations contradicted by the wheel odometry",
        c.by_odometry
    );
    eprintln!(
        "against the {} relations contradicted by neither: translation {:.4} ± {:.4} m, rotation {:.3} ± {:.3} deg",
        c.uncontradicted, c.trans_m.mean, c.trans_m.sd, c.rot_deg.mean, c.rot_deg.sd
    );
    for x in &c.contradicted {
        eprintln!(
            "  {:.3} -> {:.3}: the {} say {:.3} m / {:.2} deg from the relation; ours errs {:.3} m / {:.2} deg against the relation, {:.3} m against them",
            x.t1, x.t2, x.by, x.off_m, x.off_deg, x.ours_m, x.ours_deg, x.ours_vs_witness_m
        );
    }
    eprintln!("relations the replay misses by over 0.2 m or 2°, and what their scans say:");
    for m in &c.misses {
        let said = m
            .settled
            .map_or("the scans settle no pose".to_string(), |o| {
                format!(
                    "ours errs {:.3} m / {:.2} deg against the pose the scans settle",
                    o.trans_m, o.rot_deg
                )
            });
        eprintln!(
            "  {:.3} -> {:.3}: ours errs {:.3} m / {:.2} deg against the relation; {said}",
            m.t1, m.t2, m.trans_m, m.rot_deg
        );
    }
    Ok(())
}

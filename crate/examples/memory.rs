//! Where a run's memory goes: runs a scenario as `examples/run.rs` does
//! (simulate, then merge with the automatic method), counting every heap
//! allocation with a counting global allocator, and prints at each stage
//! the bytes live, the peak so far (a `Vec` that grows holds its old and
//! new buffers at once: the peak is what a wasm instance's linear memory,
//! which never shrinks, has to hold) and the session's own accounting,
//! component by component ([`slamlab::lab::memory`]).
//!
//! `cargo run --release -p slamlab --example memory -- SCENARIO.json [STEPS_PER_REPORT]`

use slamlab::lab::memory::MemoryUse;
use slamlab::lab::Lab;
use slamlab::merge::MergeMethod;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

/// The system allocator, counting the bytes live and their peak.
struct Counting;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

fn grew(bytes: usize) {
    let now = LIVE.fetch_add(bytes, Ordering::Relaxed) + bytes;
    PEAK.fetch_max(now, Ordering::Relaxed);
}

// SAFETY: every call is passed on to `System` unchanged; the counters are
// only arithmetic beside it.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            grew(layout.size());
        }
        p
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) };
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // A grown block may be copied: old and new exist at once.
        grew(new_size);
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        LIVE.fetch_sub(
            if p.is_null() { new_size } else { layout.size() },
            Ordering::Relaxed,
        );
        p
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

const MB: f64 = 1024.0 * 1024.0;

fn mb(b: usize) -> String {
    format!("{:.1}", b as f64 / MB)
}

fn line(stage: &str, lab: &Lab) {
    let m = lab.memory_use();
    println!(
        "{stage}: live {} MB, peak {} MB, accounted {} MB (textures {}, described {}, merge features {} of {} frames)",
        mb(LIVE.load(Ordering::Relaxed)),
        mb(PEAK.load(Ordering::Relaxed)),
        mb(m.total),
        mb(m.textures),
        mb(m.described),
        mb(m.merge_features),
        m.merge_frames_described,
    );
}

/// One row of the table: seven sizes in MB, then the frames kept.
fn print_row(name: &str, row: &[usize; 8]) {
    let sizes: Vec<String> = row[..7].iter().map(|&b| mb(b)).collect();
    println!("| {name} | {} ({}) |", sizes.join(" | "), row[7]);
}

fn table(m: &MemoryUse) {
    println!(
        "| robot | log poses | log sensors | estimates | odometry map | SLAM map | back end | frames (kept) |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    let mut sum = [0usize; 8];
    for r in &m.robots {
        let row = [
            r.log_poses,
            r.log_sensors,
            r.estimates,
            r.odometry_map,
            r.slam_map,
            r.back_end,
            r.frames,
            r.frames_kept,
        ];
        for (s, v) in sum.iter_mut().zip(row) {
            *s += v;
        }
        print_row(&r.name, &row);
    }
    print_row("all", &sum);
    println!(
        "textures {} MB, described {} MB, merge: features {} MB ({} frames), infos {} MB, cells {} MB, merged map {} MB; total {} MB",
        mb(m.textures),
        mb(m.described),
        mb(m.merge_features),
        m.merge_frames_described,
        mb(m.merge_infos),
        mb(m.merge_cells),
        mb(m.merged_map),
        mb(m.total)
    );
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let path = args
        .get(1)
        .ok_or("usage: memory SCENARIO.json [STEPS_PER_REPORT]")?;
    let every: usize = args.get(2).map_or(Ok(6000), |s| s.parse())?;
    let mut lab = Lab::new(&std::fs::read_to_string(path)?)?;
    line("start", &lab);
    while lab.step(every)? > 0 {
        let s = lab.state();
        line(&format!("t = {:.0} s", s.time_s), &lab);
    }
    table(&lab.memory_use());
    lab.merge_start(MergeMethod::parse("auto")?)?;
    while !lab.merge_advance(256)?.finished {}
    line("merged", &lab);
    table(&lab.memory_use());
    Ok(())
}

//! Saving is atomic: a process killed at random moments while saving images over and over never
//! leaves a file that fails to load, or one mixing two versions.

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Duration;

use rt_core::output::save_image;

const CHILD_ENV: &str = "RT_TEST_SAVE_LOOP";
const SIZE: u32 = 384;

/// Version `v` of the image: every pixel holds v.
fn pixels(v: u32) -> Vec<[f32; 3]> {
    vec![[v as f32, 0.5, 0.25]; (SIZE * SIZE) as usize]
}

/// Loads the file and returns its version, failing on a torn or mixed file.
fn check(path: &Path) -> u32 {
    let image = image::open(path)
        .unwrap_or_else(|e| panic!("{} does not load after a kill: {e}", path.display()));
    let rgb = image.to_rgb32f();
    assert_eq!((rgb.width(), rgb.height()), (SIZE, SIZE));
    let first = rgb.get_pixel(0, 0).0;
    assert!(
        rgb.pixels().all(|p| p.0 == first),
        "the file mixes two versions"
    );
    first[0] as u32
}

#[test]
fn killing_a_save_never_leaves_a_broken_file() {
    if let Ok(path) = std::env::var(CHILD_ENV) {
        // The child: save new versions until killed.
        for v in 1.. {
            save_image(Path::new(&path), SIZE, SIZE, &pixels(v), 0.0).unwrap();
        }
        return;
    }
    let dir = std::env::temp_dir().join(format!("rt-atomic-save-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("image.exr");
    // Kill times scale with how long a save takes here, so slow machines are tested as well.
    let started = std::time::Instant::now();
    save_image(&path, SIZE, SIZE, &pixels(0), 0.0).unwrap();
    let save_ms = started.elapsed().as_millis().max(1) as u64;
    let mut seen = std::collections::BTreeSet::new();
    let mut state = 7u32;
    for _ in 0..40 {
        let mut child = Command::new(std::env::current_exe().unwrap())
            .args([
                "--exact",
                "killing_a_save_never_leaves_a_broken_file",
                "--test-threads",
                "1",
            ])
            .env(CHILD_ENV, &path)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        state = rt_core::math::rng::pcg_hash(state);
        // Past the child's start-up, at a random point among its next few saves.
        std::thread::sleep(Duration::from_millis(
            20 + u64::from(state) % (12 * save_ms),
        ));
        child.kill().unwrap();
        child.wait().unwrap();
        seen.insert(check(&path));
    }
    // Some kills must have landed after saves (a new version survived), or the test proved little.
    assert!(
        seen.len() >= 2,
        "no kill landed after a save: {seen:?} (save takes {save_ms} ms)"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A killed save leaves `.NAME.HOST-PID.tmp` behind; the next save of that file removes the
/// leftovers of this machine's processes that are gone, and leaves those of running ones, and
/// recent ones of other machines sharing the directory, alone.
#[cfg(target_os = "linux")]
#[test]
fn the_next_save_removes_temporaries_of_killed_saves() {
    let dir = std::env::temp_dir().join(format!("rt-stale-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let target = dir.join("out.png");
    // PIDs above the kernel's maximum (4,194,304) never run; PID 1 always does.
    let host = rt_core::output::host_name();
    let stale = dir.join(format!(".out.png.{host}-999999999.tmp"));
    let running = dir.join(format!(".out.png.{host}-1.tmp"));
    let other = dir.join(format!(".other.png.{host}-999999999.tmp"));
    let elsewhere = dir.join(".out.png.another-host-999999999.tmp");
    for f in [&stale, &running, &other, &elsewhere] {
        std::fs::write(f, b"partial").unwrap();
    }
    rt_core::output::save_image(&target, 1, 1, &[[0.5; 3]], 0.0).unwrap();
    assert!(target.exists());
    assert!(!stale.exists(), "the dead process's temporary is removed");
    assert!(running.exists(), "a running process's temporary is kept");
    assert!(other.exists(), "other files' temporaries are not touched");
    assert!(
        elsewhere.exists(),
        "another machine's recent temporary is not judged by this machine's processes"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

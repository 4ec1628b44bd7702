//! Stopping at a noise target or time limit, `converge`'s CSV and plot, verbose timing.

use super::*;

/// Reads "image: WxH, N spp" and "noise: X" from the summary.
fn spp_and_noise(stderr: &str) -> (u32, f64) {
    let spp = stderr
        .lines()
        .find(|l| l.starts_with("image:"))
        .and_then(|l| l.split(", ").nth(1))
        .and_then(|s| s.trim_end_matches(" spp").parse().ok())
        .unwrap_or_else(|| panic!("no spp in {stderr}"));
    let noise = stderr
        .lines()
        .find(|l| l.starts_with("noise:"))
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("no noise in {stderr}"));
    (spp, noise)
}

/// `--noise-target` stops once the estimated noise is at or under the target, and a stricter
/// target takes more samples; `--time-limit` stops an otherwise endless render. Checked by the
/// samples taken and the error estimate, not by the clock.
#[test]
fn noise_target_and_time_limit_stop_the_render() {
    if !has_gpu() {
        return;
    }
    let dir = temp_dir("stop");
    let out = dir.join("img.png");
    let out = out.to_str().unwrap();
    let run = |extra: &[&str]| {
        let mut args = vec![
            "render",
            "-o",
            out,
            "--width",
            "24",
            "--height",
            "24",
            "--adapter",
            "cpu",
        ];
        args.extend_from_slice(extra);
        let (code, _, stderr) = rt_cli(&args);
        assert_eq!(code, 0, "{stderr}");
        stderr
    };
    let loose = run(&["--noise-target", "0.3"]);
    let strict = run(&["--noise-target", "0.15"]);
    let (spp_loose, noise_loose) = spp_and_noise(&loose);
    let (spp_strict, noise_strict) = spp_and_noise(&strict);
    assert!(
        loose.contains("stopped by noise target") && strict.contains("stopped by noise target")
    );
    assert!(
        noise_loose <= 0.3 && noise_strict <= 0.15,
        "{noise_loose} {noise_strict}"
    );
    assert!(
        spp_strict > spp_loose,
        "a stricter target must take more samples: {spp_strict} vs {spp_loose}"
    );
    // The same seed with fewer samples than the stop was noisier than the target.
    let (_, noise_fewer) =
        spp_and_noise(&run(&["--spp", &(spp_strict * 3 / 4).max(1).to_string()]));
    assert!(
        noise_fewer > 0.15,
        "{} spp already had noise {noise_fewer}",
        spp_strict * 3 / 4
    );

    let timed = run(&["--time-limit", "0.5", "--spp", "1000000"]);
    let (spp_timed, _) = spp_and_noise(&timed);
    assert!(
        timed.contains("stopped by time limit") && spp_timed < 1_000_000,
        "{timed}"
    );
    let (code, _, stderr) = rt_cli(&["render", "-o", out, "--time-limit=-1"]);
    assert!(code == 2 && stderr.contains("--time-limit"), "{stderr}");
}

/// `converge` measures each power-of-two step against a reference, appends CSV rows and plots them;
/// `render` renders a project file with the project's own settings.
#[test]
fn converge_writes_csv_and_plot_and_render_reads_projects() {
    if !has_gpu() {
        return;
    }
    let dir = temp_dir("converge");
    let reference = dir.join("ref.exr");
    let (code, stderr) = render_cornell(32, 32, 64, &reference, &[]);
    assert_eq!(code, 0, "{stderr}");
    let csv = dir.join("c.csv");
    let svg = dir.join("c.svg");
    let (code, stdout, stderr) = rt_cli(&[
        "converge",
        "--reference",
        reference.to_str().unwrap(),
        "--width",
        "32",
        "--height",
        "32",
        "--max-spp",
        "8",
        "--label",
        "test",
        "--csv",
        csv.to_str().unwrap(),
        "--plot",
        svg.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert_eq!(
        stdout.lines().count(),
        5,
        "header and 1, 2, 4, 8 spp:\n{stdout}"
    );
    let rows: Vec<String> = std::fs::read_to_string(&csv)
        .unwrap()
        .lines()
        .map(String::from)
        .collect();
    assert_eq!(rows.len(), 5);
    assert!(rows[0].starts_with("label,spp,seconds,rel_mse"));
    let rel_mse = |row: &str| row.split(',').nth(3).unwrap().parse::<f64>().unwrap();
    assert!(
        rel_mse(&rows[4]) < rel_mse(&rows[1]),
        "error falls with samples: {rows:?}"
    );
    assert!(std::fs::read_to_string(&svg).unwrap().contains("<polyline"));

    // A project with its own size and samples renders as saved.
    let mut scene = rt_io::assets::cornell_box().unwrap();
    scene.settings.width = 24;
    scene.settings.height = 16;
    scene.settings.samples_per_pixel = 3;
    let project = dir.join("p.rtproj");
    rt_io::project::save_project(&scene, &project).unwrap();
    let out = dir.join("p.png");
    let (code, _, stderr) = rt_cli(&[
        "render",
        project.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stderr.contains("24x16, 3 spp"), "{stderr}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `-v` reports the longest dispatch (the figure that must stay well under an OS GPU watchdog's
/// ~100 ms on a real GPU; sized to ~40 ms, see docs/robustness.md), with its unit.
#[test]
fn a_verbose_render_reports_its_longest_dispatch() {
    if !has_gpu() {
        return;
    }
    let dir = temp_dir("verbose");
    let out = dir.join("v.png");
    let (code, stderr) = render_cornell(32, 32, 8, &out, &["-v", "--device", "gpu"]);
    assert_eq!(code, 0, "{stderr}");
    let line = stderr
        .lines()
        .find(|l| l.starts_with("longest dispatch:"))
        .unwrap_or_else(|| panic!("no longest dispatch in: {stderr}"));
    assert!(line.ends_with('s'), "{line}");
    std::fs::remove_dir_all(&dir).unwrap();
}

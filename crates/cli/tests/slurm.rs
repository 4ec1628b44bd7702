//! A real batch system: a one-node Slurm cluster on localhost, started here (munged, slurmctld,
//! slurmd, private to the test), runs `deploy/slurm/submit.sh`: a 4-task render array and the
//! merge that depends on it. The merged frame must be the one-process render's samples, bit for
//! bit. The daemons are stopped by their PIDs when the test ends, pass or fail.
//!
//! Needs Debian's slurmctld, slurmd, slurm-client and munge (`scripts/ensure-slurm`, which the test
//! script runs) and root (slurmd launches jobs as their user); without them the test says why and
//! passes, except under CI, where it fails.
#![expect(
    clippy::unwrap_used,
    reason = "test helpers fail the test on unexpected errors"
)]

mod common;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use common::{has_gpu, render_cornell, temp_dir};

/// Why the cluster cannot run here, if it cannot.
fn missing_prerequisite() -> Option<String> {
    for tool in ["munged", "slurmctld", "slurmd", "sbatch", "squeue"] {
        let found = ["/usr/sbin", "/usr/bin", "/sbin", "/bin"]
            .iter()
            .any(|d| Path::new(d).join(tool).exists());
        if !found {
            return Some(format!(
                "{tool} is not installed (scripts/ensure-slurm installs Slurm and munge)"
            ));
        }
    }
    let uid = Command::new("id").arg("-u").output().ok()?;
    if String::from_utf8_lossy(&uid.stdout).trim() != "0" {
        return Some("slurmd must run as root to launch jobs".into());
    }
    None
}

/// The daemons this test started, stopped by PID when dropped.
struct Cluster {
    dir: PathBuf,
    conf: PathBuf,
    pids: Vec<(String, PathBuf)>,
}

impl Drop for Cluster {
    fn drop(&mut self) {
        for (name, pid_file) in self.pids.iter().rev() {
            let Some(pid) = std::fs::read_to_string(pid_file)
                .ok()
                .and_then(|p| p.trim().parse::<u32>().ok())
            else {
                eprintln!("slurm test: no PID file for {name}");
                continue;
            };
            let _ = Command::new("kill").arg(pid.to_string()).status();
            let gone = Instant::now();
            while Path::new(&format!("/proc/{pid}")).exists() && gone.elapsed().as_secs() < 10 {
                std::thread::sleep(Duration::from_millis(50));
            }
        }
    }
}

/// A TCP port nobody listens on now.
fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port()
}

fn run(cmd: &mut Command, what: &str) -> Result<String, String> {
    let out = cmd.output().map_err(|e| format!("{what}: {e}"))?;
    if !out.status.success() {
        return Err(format!(
            "{what} failed ({}): {}{}",
            out.status,
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    Ok(String::from_utf8_lossy(&out.stdout).into())
}

/// Starts munged, slurmctld and slurmd on localhost, with state, logs and sockets in `dir`.
fn start_cluster(dir: &Path) -> Result<Cluster, String> {
    let munge = dir.join("munge");
    std::fs::create_dir_all(&munge).unwrap();
    let sh = |script: &str| run(Command::new("sh").args(["-c", script]), script);
    // A key of its own: the test's cluster shares nothing with one the machine may run.
    sh(&format!(
        "chmod 711 {m} && dd if=/dev/urandom of={m}/munge.key bs=1024 count=1 status=none && \
         chmod 600 {m}/munge.key",
        m = munge.display()
    ))?;
    let socket = munge.join("munge.socket");
    let mut cluster = Cluster {
        dir: dir.into(),
        conf: dir.join("slurm.conf"),
        pids: vec![],
    };
    run(
        Command::new("munged")
            .arg("--force")
            .arg(format!("--socket={}", socket.display()))
            .arg(format!("--key-file={}", munge.join("munge.key").display()))
            .arg(format!("--log-file={}", munge.join("munged.log").display()))
            .arg(format!("--pid-file={}", munge.join("munged.pid").display()))
            .arg(format!(
                "--seed-file={}",
                munge.join("munged.seed").display()
            )),
        "munged",
    )?;
    cluster
        .pids
        .push(("munged".into(), munge.join("munged.pid")));
    let d = dir.display();
    let cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
    let conf = format!(
        "ClusterName=rt-test\nSlurmctldHost=localhost\nSlurmUser=root\nSlurmdUser=root\n\
         SlurmctldPort={ctld}\nSlurmdPort={slurmd}\n\
         AuthType=auth/munge\nAuthInfo=socket={socket}\nCredType=cred/munge\n\
         ProctrackType=proctrack/linuxproc\nTaskPlugin=task/none\n\
         SelectType=select/cons_tres\nSelectTypeParameters=CR_Core\nSchedulerType=sched/builtin\n\
         MpiDefault=none\nReturnToService=2\n\
         StateSaveLocation={d}/state\nSlurmdSpoolDir={d}/spool\n\
         SlurmctldPidFile={d}/slurmctld.pid\nSlurmdPidFile={d}/slurmd.pid\n\
         SlurmctldLogFile={d}/slurmctld.log\nSlurmdLogFile={d}/slurmd.log\n\
         JobCompType=jobcomp/none\nAccountingStorageType=accounting_storage/none\n\
         JobAcctGatherType=jobacct_gather/none\n\
         NodeName=localhost CPUs={cpus} RealMemory=1000 State=UNKNOWN\n\
         PartitionName=rt Nodes=localhost Default=YES MaxTime=INFINITE State=UP\n",
        ctld = free_port(),
        slurmd = free_port(),
        socket = socket.display(),
    );
    std::fs::write(&cluster.conf, conf).unwrap();
    for sub in ["state", "spool"] {
        std::fs::create_dir_all(dir.join(sub)).unwrap();
    }
    run(
        Command::new("slurmctld").arg("-f").arg(&cluster.conf),
        "slurmctld",
    )?;
    cluster
        .pids
        .push(("slurmctld".into(), dir.join("slurmctld.pid")));
    run(
        Command::new("slurmd")
            .arg("-f")
            .arg(&cluster.conf)
            .args(["-N", "localhost"]),
        "slurmd",
    )?;
    cluster.pids.push(("slurmd".into(), dir.join("slurmd.pid")));
    // Up when the node is idle.
    let started = Instant::now();
    loop {
        let state = run(
            Command::new("sinfo")
                .env("SLURM_CONF", &cluster.conf)
                .args(["-h", "-o", "%T"]),
            "sinfo",
        )
        .unwrap_or_default();
        if state.trim() == "idle" {
            return Ok(cluster);
        }
        if started.elapsed().as_secs() > 30 {
            return Err(format!(
                "the node did not come up (state '{}'); {}",
                state.trim(),
                cluster.logs()
            ));
        }
        std::thread::sleep(Duration::from_millis(200));
    }
}

impl Cluster {
    fn logs(&self) -> String {
        ["slurmctld.log", "slurmd.log"]
            .iter()
            .map(|f| {
                let text = std::fs::read_to_string(self.dir.join(f)).unwrap_or_default();
                let tail: Vec<&str> = text.lines().rev().take(15).collect();
                format!(
                    "--- {f}:\n{}",
                    tail.into_iter().rev().collect::<Vec<_>>().join("\n")
                )
            })
            .collect::<Vec<_>>()
            .join("\n")
    }
}

#[test]
fn a_slurm_job_array_and_its_merge_render_the_one_machine_frame() {
    if let Some(why) = missing_prerequisite() {
        assert!(
            std::env::var_os("CI").is_none(),
            "the Slurm test cannot run under CI: {why}"
        );
        eprintln!("skipping the Slurm test: {why}");
        return;
    }
    if !has_gpu() {
        return;
    }
    let dir = temp_dir("slurm");
    let cluster = match start_cluster(&dir.join("cluster")) {
        Ok(c) => c,
        Err(e) => panic!("the one-node Slurm cluster did not start: {e}"),
    };
    let parts = dir.join("parts");
    let output = dir.join("frame.exr");
    let submit = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../deploy/slurm/submit.sh");
    let submitted = run(
        Command::new(&submit)
            .arg("4")
            .env("SLURM_CONF", &cluster.conf)
            .env("RT_CLI", env!("CARGO_BIN_EXE_rt-cli"))
            .env("RT_SPP", "9")
            .env("RT_ARGS", "--width 32 --height 24")
            .env("RT_PARTS", &parts)
            .env("RT_OUTPUT", &output),
        "deploy/slurm/submit.sh",
    )
    .unwrap();
    assert!(submitted.contains("merge"), "{submitted}");
    // Wait for the queue to empty (the merge runs last).
    let started = Instant::now();
    loop {
        let queue = run(
            Command::new("squeue")
                .env("SLURM_CONF", &cluster.conf)
                .args(["-h", "-o", "%i %T %r"]),
            "squeue",
        )
        .unwrap();
        if queue.trim().is_empty() {
            break;
        }
        assert!(
            started.elapsed().as_secs() < 300,
            "the jobs did not finish in 5 minutes:\n{queue}\n{}",
            cluster.logs()
        );
        std::thread::sleep(Duration::from_millis(500));
    }
    let merge_log = std::fs::read_to_string(parts.join("merge.log")).unwrap_or_default();
    let render_log = std::fs::read_to_string(parts.join("render-0.log")).unwrap_or_default();
    assert!(
        output.is_file(),
        "no merged frame; first render task's log:\n{render_log}\nmerge log:\n{merge_log}\n{}",
        cluster.logs()
    );
    assert!(merge_log.contains("the whole frame"), "{merge_log}");
    for i in 0..4 {
        assert!(parts.join(format!("part-{i:05}.exr")).is_file());
    }
    let one_process = dir.join("one.exr");
    let (code, stderr) = render_cornell(32, 24, 9, &one_process, &["--shard", "0/1"]);
    assert_eq!(code, 0, "{stderr}");
    let merged = rt_core::part::read_part(&output).unwrap();
    let one = rt_core::part::read_part(&one_process).unwrap();
    assert!(
        merged.counts == one.counts && merged.sums == one.sums,
        "the cluster's merged frame differs from the one-process render"
    );
    drop(cluster);
    std::fs::remove_dir_all(&dir).ok();
}

//! Studies through a real single-node Slurm cluster on this machine: Debian's `slurm-wlm`
//! and `munge` (munged, slurmctld and slurmd on localhost, a generated `slurm.conf` in a
//! temporary folder, one partition with the machine's CPUs).
//!
//! * `slurm_sweep_matches_a_local_run`: a small sweep submitted with
//!   `scripts/slurm/submit.sh`; `report --from`'s numbers equal, byte for byte, those of
//!   the same plan run locally with `run-job`.
//! * `slurm_cancelled_study_resumes_cleanly`: the array is cancelled while it runs, then
//!   resubmitted; the study completes with one valid result per entry and nothing else.
//!
//! Skipped (reported as ignored, with the reason) where Slurm or munge is not installed or
//! the test does not run as root (slurmd must); under `CI` a missing Slurm is a failure.
//! Every daemon the test starts is stopped by the pid it wrote, never by name.

use libtest_mimic::{Arguments, Failed, Trial};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const BIN: &str = env!("CARGO_BIN_EXE_dualsplit");
/// Longest wait for the cluster to come up or a study to finish (a safeguard against a
/// hung scheduler, not a performance bound).
const WAIT: Duration = Duration::from_secs(600);

fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn have(cmd: &str) -> bool {
    ["/usr/sbin", "/usr/bin", "/sbin", "/bin"]
        .iter()
        .any(|d| Path::new(d).join(cmd).exists())
}

/// Why the cluster cannot be started here, if it cannot.
fn missing() -> Option<String> {
    let absent: Vec<&str> = [
        "slurmctld",
        "slurmd",
        "sbatch",
        "squeue",
        "scancel",
        "munged",
    ]
    .into_iter()
    .filter(|c| !have(c))
    .collect();
    if !absent.is_empty() {
        return Some(format!(
            "not installed: {} (apt-get install slurm-wlm munge)",
            absent.join(", ")
        ));
    }
    let uid = Command::new("id").arg("-u").output().ok()?;
    if String::from_utf8_lossy(&uid.stdout).trim() != "0" {
        return Some("slurmd needs root".into());
    }
    None
}

fn sh(cmd: &str, env: &[(&str, &str)]) -> Result<String, Failed> {
    let mut c = Command::new("bash");
    c.arg("-c").arg(cmd);
    for (k, v) in env {
        c.env(k, v);
    }
    let out = c.output().map_err(|e| format!("{cmd}: {e}"))?;
    if !out.status.success() {
        return Err(format!(
            "`{cmd}` failed ({}): {}{}",
            out.status,
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        )
        .into());
    }
    Ok(String::from_utf8_lossy(&out.stdout).into_owned())
}

fn wait_for(what: &str, mut ready: impl FnMut() -> bool) -> Result<(), Failed> {
    let t0 = Instant::now();
    while !ready() {
        if t0.elapsed() > WAIT {
            return Err(format!("gave up waiting for {what}").into());
        }
        std::thread::sleep(Duration::from_millis(500));
    }
    Ok(())
}

/// A running single-node cluster; dropping it stops what it started.
struct Cluster {
    dir: tempfile::TempDir,
    conf: PathBuf,
    munged_pid: Option<PathBuf>,
}

impl Cluster {
    fn start() -> Result<Self, Failed> {
        let dir = tempfile::tempdir()?;
        let t = dir.path().to_string_lossy().into_owned();
        let host = sh("hostname -s", &[])?.trim().to_string();
        let cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
        // Ports of our own, so that a cluster started beside this one does not collide.
        let port = 20000 + (std::process::id() % 5000) * 2;
        let mut cluster = Cluster {
            conf: dir.path().join("slurm.conf"),
            dir,
            munged_pid: None,
        };
        // munged: reuse a running one (its socket answers), else start one with its own
        // pid file.
        if sh("munge -n | unmunge", &[]).is_err() {
            let pid = PathBuf::from(format!(
                "/run/munge/dualsplit-test-{}.pid",
                std::process::id()
            ));
            sh(
                "mkdir -p /etc/munge /run/munge /var/log/munge /var/lib/munge && \
                 { [ -f /etc/munge/munge.key ] || dd if=/dev/urandom bs=1 count=1024 of=/etc/munge/munge.key 2>/dev/null; } && \
                 chown -R munge:munge /etc/munge /run/munge /var/log/munge /var/lib/munge && chmod 400 /etc/munge/munge.key",
                &[],
            )?;
            sh(
                &format!(
                    "su -s /bin/sh munge -c '/usr/sbin/munged --pid-file={}'",
                    pid.display()
                ),
                &[],
            )?;
            cluster.munged_pid = Some(pid);
            wait_for("munged", || sh("munge -n | unmunge", &[]).is_ok())?;
        }
        let conf = format!(
            "ClusterName=dstest\nSlurmctldHost={host}\nSlurmctldPort={port}\nSlurmdPort={}\n\
             SlurmUser=root\nSlurmdUser=root\nAuthType=auth/munge\n\
             StateSaveLocation={t}/state\nSlurmdSpoolDir={t}/spool\n\
             SlurmctldPidFile={t}/slurmctld.pid\nSlurmdPidFile={t}/slurmd.pid\n\
             SlurmctldLogFile={t}/slurmctld.log\nSlurmdLogFile={t}/slurmd.log\n\
             ProctrackType=proctrack/linuxproc\nTaskPlugin=task/none\n\
             SchedulerType=sched/backfill\nSelectType=select/cons_tres\nSelectTypeParameters=CR_Core\n\
             ReturnToService=2\nMpiDefault=none\nJobCompType=jobcomp/none\n\
             AccountingStorageType=accounting_storage/none\n\
             NodeName={host} CPUs={cpus} RealMemory=4000 State=UNKNOWN\n\
             PartitionName=dstest Nodes={host} Default=YES MaxTime=INFINITE State=UP\n",
            port + 1
        );
        std::fs::create_dir_all(cluster.dir.path().join("state"))?;
        std::fs::create_dir_all(cluster.dir.path().join("spool"))?;
        std::fs::write(&cluster.conf, conf)?;
        cluster.run("/usr/sbin/slurmctld -i")?;
        wait_for("slurmctld", || cluster.run("sinfo -h").is_ok())?;
        cluster.run("/usr/sbin/slurmd")?;
        wait_for("the node to be idle", || {
            cluster
                .run("sinfo -h -o %T")
                .is_ok_and(|s| s.trim() == "idle")
        })?;
        Ok(cluster)
    }

    fn env(&self) -> [(&str, String); 1] {
        [("SLURM_CONF", self.conf.to_string_lossy().into_owned())]
    }

    fn run(&self, cmd: &str) -> Result<String, Failed> {
        let [(k, v)] = self.env();
        sh(cmd, &[(k, &v)])
    }

    /// Submits the study in `dir`; returns (array job id, report job id).
    fn submit(&self, dir: &Path, limit: u32) -> Result<(String, String), Failed> {
        let script = repo_root().join("scripts/slurm/submit.sh");
        let [(k, v)] = self.env();
        let out = sh(
            &format!(
                "'{}' '{}' --mem=200M --time=10",
                script.display(),
                dir.display()
            ),
            &[(k, &v), ("DUALSPLIT", BIN), ("LIMIT", &limit.to_string())],
        )?;
        let id = |tag: &str| {
            out.lines()
                .find_map(|l| l.strip_prefix(tag).map(|s| s.trim().to_string()))
                .ok_or_else(|| Failed::from(format!("submit.sh printed no {tag}job id: {out}")))
        };
        Ok((id("array ")?, id("report ")?))
    }

    /// Waits until none of `jobs` is queued or running.
    fn wait_gone(&self, jobs: &[&str]) -> Result<(), Failed> {
        let list = jobs.join(",");
        wait_for(&format!("jobs {list}"), || {
            self.run(&format!("squeue -h -j {list}"))
                .is_ok_and(|s| s.trim().is_empty())
        })
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        // Stop exactly what this test started, by pid file.
        for pidfile in [
            Some(self.dir.path().join("slurmd.pid")),
            Some(self.dir.path().join("slurmctld.pid")),
            self.munged_pid.clone(),
        ]
        .into_iter()
        .flatten()
        {
            if let Ok(pid) = std::fs::read_to_string(&pidfile) {
                let pid = pid.trim();
                if !pid.is_empty() && pid.chars().all(|c| c.is_ascii_digit()) {
                    let _ = Command::new("kill").arg(pid).stderr(Stdio::null()).status();
                    // Give the daemon a moment to exit before its files are removed.
                    for _ in 0..20 {
                        let alive = Path::new(&format!("/proc/{pid}")).exists();
                        if !alive {
                            break;
                        }
                        std::thread::sleep(Duration::from_millis(100));
                    }
                }
            }
        }
    }
}

fn dualsplit(args: &[&str]) -> Result<std::process::Output, Failed> {
    Ok(Command::new(BIN).arg("--quiet").args(args).output()?)
}

fn plan(dir: &Path, extra: &[&str]) -> Result<usize, Failed> {
    let d = dir.to_string_lossy();
    let mut args = vec![
        "plan",
        "builtin:cornell",
        "--tms",
        "4",
        "--accel",
        "bvh2,dst",
        "--out",
        &d,
    ];
    args.extend_from_slice(extra);
    let out = dualsplit(&args)?;
    if !out.status.success() {
        return Err(format!("plan: {}", String::from_utf8_lossy(&out.stderr)).into());
    }
    let plan: serde_json::Value = serde_json::from_slice(&std::fs::read(dir.join("plan.json"))?)?;
    Ok(plan["entries"].as_array().map_or(0, Vec::len))
}

/// Result files in the study's cache (not temporary files), and every file's name.
fn cache_files(dir: &Path) -> Result<(Vec<String>, Vec<String>), Failed> {
    let mut all: Vec<String> = std::fs::read_dir(dir.join("cache"))?
        .map(|e| e.map(|e| e.file_name().to_string_lossy().into_owned()))
        .collect::<Result<_, _>>()?;
    all.sort();
    let results = all
        .iter()
        .filter(|n| !n.starts_with('.'))
        .cloned()
        .collect();
    Ok((results, all))
}

fn sweep_matches_local(cluster: &Cluster) -> Result<(), Failed> {
    let tmp = tempfile::tempdir()?;
    let (slurm, local) = (tmp.path().join("slurm"), tmp.path().join("local"));
    let sweep = [
        "--res",
        "24",
        "--workload",
        "path",
        "--vary",
        "l1.size_bytes=4096,65536",
    ];
    let n = plan(&slurm, &sweep)?;
    assert_eq!(n, 4, "2 configurations × 2 cache sizes");
    assert_eq!(plan(&local, &sweep)?, n);
    let (array, report) = cluster.submit(&slurm, 2)?;
    cluster.wait_gone(&[&array, &report])?;
    let page = slurm.join("report");
    if !page.join("results.json").exists() {
        let logs = sh(&format!("cat '{}'/slurm/* 2>&1", slurm.display()), &[]).unwrap_or_default();
        return Err(format!("the report job wrote no results.json; job output:\n{logs}").into());
    }
    for i in 0..n {
        let out = dualsplit(&["run-job", &local.to_string_lossy(), &i.to_string()])?;
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let out = dualsplit(&["report", "--from", &local.to_string_lossy()])?;
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for f in ["results.json", "results.csv"] {
        let a = std::fs::read(page.join(f))?;
        let b = std::fs::read(local.join("report").join(f))?;
        assert!(
            a == b,
            "{f} differs between the Slurm run and the local run"
        );
    }
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(page.join("results.json"))?)?;
    assert_eq!(json["rows"].as_array().map_or(0, Vec::len), n);
    assert!(json["missing"].as_array().is_some_and(Vec::is_empty));
    // The sweep chart: one per (scene, workload) of the swept key, in both formats.
    assert!(page.join("sweep-0.svg").exists() && page.join("sweep-0.png").exists());
    let html = std::fs::read_to_string(page.join("index.html"))?;
    assert!(
        html.contains("l1.size_bytes: cornell path"),
        "no sweep chart on the page"
    );
    let (results, all) = cache_files(&slurm)?;
    assert_eq!(results.len(), n);
    assert_eq!(all.len(), n, "temporary files left: {all:?}");
    Ok(())
}

fn cancelled_study_resumes(cluster: &Cluster) -> Result<(), Failed> {
    let tmp = tempfile::tempdir()?;
    let dir = tmp.path().join("study");
    // The instruction-level model at 160² takes seconds per frame, so the array is
    // cancelled with a task in the middle of its simulation.
    let n = plan(
        &dir,
        &[
            "--res",
            "160",
            "--model",
            "rv32",
            "--workload",
            "path",
            "--vary",
            "units.dst_pipes=1,2,4",
        ],
    )?;
    assert_eq!(n, 6);
    let (array, report) = cluster.submit(&dir, 1)?;
    wait_for("the first result", || {
        cache_files(&dir).is_ok_and(|(r, _)| !r.is_empty())
    })?;
    cluster.run(&format!("scancel {array} {report}"))?;
    cluster.wait_gone(&[&array, &report])?;
    // Whatever the cancellation left is either a valid result or absent: report --from
    // lists the rest as missing, none as invalid.
    let out = dualsplit(&["report", "--from", &dir.to_string_lossy()])?;
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(
        out.status.code(),
        Some(2),
        "incomplete study must exit 2: {stderr}"
    );
    assert!(
        stderr.contains("missing:") && !stderr.contains("invalid:"),
        "{stderr}"
    );
    let (before, _) = cache_files(&dir)?;
    assert!(
        !before.is_empty() && before.len() < n,
        "{} results after the cancel",
        before.len()
    );

    let (array, report) = cluster.submit(&dir, 2)?;
    cluster.wait_gone(&[&array, &report])?;
    let (results, _) = cache_files(&dir)?;
    assert_eq!(results.len(), n, "one result per entry: {results:?}");
    for f in &before {
        assert!(results.contains(f));
    }
    let out = dualsplit(&["report", "--from", &dir.to_string_lossy()])?;
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("report/results.json"))?)?;
    let mut idx: Vec<u64> = json["rows"]
        .as_array()
        .map(|r| r.iter().filter_map(|x| x["index"].as_u64()).collect())
        .unwrap_or_default();
    idx.dedup();
    assert_eq!(idx, (0..n as u64).collect::<Vec<_>>(), "each entry once");
    assert!(json["invalid"].as_array().is_some_and(Vec::is_empty));
    Ok(())
}

fn main() {
    let mut args = Arguments::from_args();
    // One cluster, one study at a time.
    args.test_threads = Some(1);
    let names = [
        "slurm_sweep_matches_a_local_run",
        "slurm_cancelled_study_resumes_cleanly",
    ];
    let why_not = missing();
    if let Some(why) = &why_not {
        if std::env::var_os("CI").is_some() {
            eprintln!("slurm tests: required under CI, but {why}");
            std::process::exit(1);
        }
        eprintln!("slurm tests skipped: {why}");
        let trials = names
            .iter()
            .map(|n| Trial::test(*n, || Ok(())).with_ignored_flag(true))
            .collect();
        libtest_mimic::run(&args, trials).exit();
    }
    let filtered = |n: &str| args.filter.as_deref().is_none_or(|f| n.contains(f));
    if !names.iter().any(|n| filtered(n)) || args.list {
        let trials = names.iter().map(|n| Trial::test(*n, || Ok(()))).collect();
        libtest_mimic::run(&args, trials).exit();
    }
    let cluster = match Cluster::start() {
        Ok(c) => std::sync::Arc::new(c),
        Err(e) => {
            eprintln!(
                "could not start the single-node Slurm cluster: {}",
                e.message().unwrap_or("")
            );
            std::process::exit(1);
        }
    };
    let c1 = cluster.clone();
    let c2 = cluster.clone();
    let trials = vec![
        Trial::test(names[0], move || sweep_matches_local(&c1)),
        Trial::test(names[1], move || cancelled_study_resumes(&c2)),
    ];
    let conclusion = libtest_mimic::run(&args, trials);
    drop(cluster);
    conclusion.exit();
}

//! Under CPU load (`-- --load`): a CPU hog per CPU, with and without the partitions' real-time
//! settings, and the table of the three cases.

use super::*;

/// Applies the real-time settings of `--load` to the calling thread and process, through the
/// partitions' own module, with `cpu` as the affinity; what it got (and the warnings of what
/// was not granted) for the results.
pub(super) fn apply_realtime(side: &str, cpu: usize) -> Value {
    let settings = RealtimeSettings {
        cpus: vec![cpu],
        fifo_priority: FifoPriority::new(LOAD_FIFO_PRIORITY),
        lock_memory: true,
    };
    let applied = realtime::apply(&settings);
    let warnings: Vec<String> = applied.warnings.iter().map(ToString::to_string).collect();
    for w in &warnings {
        eprintln!("{side}: real-time setting not granted in full: {w}");
    }
    json!({ "got": applied.got.to_string(), "warnings": warnings })
}

/// A hog: pins itself to `cpu`, says it is ready, and spins until it is killed or its parent,
/// the bench, is gone.
pub(super) fn hog_main(cpu: Option<usize>) {
    if let Some(cpu) = cpu {
        if let Err(e) = pin_to(cpu) {
            eprintln!("hog: cannot pin to CPU {cpu}: {e}");
        }
    }
    let scheduling = realtime::observe().scheduling;
    assert_eq!(
        scheduling,
        Scheduling::Other,
        "a hog must run at default scheduling"
    );
    println!("ready");
    let parent = rustix::process::getppid();
    let mut x: u64 = 0;
    loop {
        for _ in 0..10_000_000 {
            x = std::hint::black_box(x.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1));
        }
        if rustix::process::getppid() != parent {
            return;
        }
    }
}

/// The hogs of a case, one per CPU; killed when dropped (see [`ChildGuard`]), so a panic of
/// the bench leaves none behind.
pub(super) struct Hogs {
    _guards: Vec<ChildGuard>,
}

impl Hogs {
    /// Starts a hog on each of `cpus` and waits until each is spinning.
    fn start(cpus: &[usize]) -> Self {
        let mut hogs = Vec::new();
        for &cpu in cpus {
            let mut command = Command::new(std::env::current_exe().expect("own executable"));
            command
                .args(["--role", "hog", "--cpu", &cpu.to_string()])
                .stdout(Stdio::piped());
            let mut hog = ChildGuard(command.spawn().expect("start a hog"));
            let stdout = hog.0.stdout.take().expect("piped stdout");
            // Pushed first, so that a hog that fails to start is killed with the others.
            hogs.push(hog);
            let mut line = String::new();
            BufReader::new(stdout)
                .read_line(&mut line)
                .expect("the hog's output");
            assert_eq!(line.trim(), "ready", "the hog on CPU {cpu} did not start");
        }
        Self { _guards: hogs }
    }
}

/// The cases of `--load`, in the order they run: the real-time one last, since the sender (this
/// process) keeps its settings.
pub(super) const LOAD_CASES: [(&str, &str, bool, bool); 3] = [
    ("idle-default", "no load, default scheduling", false, false),
    ("load-default", "CPU hogs, default scheduling", true, false),
    ("load-realtime", "CPU hogs, real-time settings", true, true),
];

/// `--load`: the hop of the largest STANAG frame over iceoryx2 event-driven in the cases of
/// [`LOAD_CASES`].
pub(super) fn load_main(transport: Transport, frames: u64, warmup: u64) {
    let allowed: Vec<usize> = rustix::thread::sched_getaffinity(None)
        .map(|set| {
            (0..rustix::thread::CpuSet::MAX_CPU)
                .filter(|&c| set.is_set(c))
                .collect()
        })
        .unwrap_or_default();
    let (sender_cpu, receiver_cpu) = cpu_pair().expect("two CPUs for the real-time case");
    let load_before = load_average();
    println!(
        "Partition-to-partition hop under CPU load: {} ({}), {MAX_FRAME_LEN} B frames, {frames} frames per case \
         after {warmup} warm-up frames, each sent after the previous one was answered. CPU hogs: \
         one busy process per CPU ({}), default scheduling. Real-time settings (the partitions' \
         realtime module): sender on CPU {sender_cpu}, receiver on CPU {receiver_cpu}, \
         SCHED_FIFO priority {LOAD_FIFO_PRIORITY}, memory locked; default scheduling: not \
         pinned. Load average before: {load_before}",
        transport.label(),
        transport.arg(),
        realtime::CpuList(&allowed)
    );
    let pid = std::process::id();
    let mut results = Vec::new();
    for (key, label, load, rt) in LOAD_CASES {
        let started = Instant::now();
        let hogs = load.then(|| Hogs::start(&allowed));
        let sender_realtime = if rt {
            apply_realtime("sender", sender_cpu)
        } else {
            Value::Null
        };
        let run = Run {
            transport,
            size: MAX_FRAME_LEN,
            frames,
            warmup,
            id: format!("{pid}-load-{key}"),
            realtime: rt,
        };
        let mut result = measure(&run, rt.then_some(receiver_cpu));
        drop(hogs);
        result["case"] = json!(key);
        result["case_label"] = json!(label);
        result["hogs"] = json!(if load { allowed.len() } else { 0 });
        result["sender_realtime"] = sender_realtime;
        eprintln!(
            "  {label:<30} p50 {:>9.2} µs  p99.9 {:>9.2} µs  ({:.1} s)",
            us(&result, "p50_ns"),
            us(&result, "p999_ns"),
            started.elapsed().as_secs_f64()
        );
        results.push(result);
    }
    print_load_table(&results);
    let load_after = load_average();
    println!("Load average after: {load_after}");

    let document = json!({
        "what": "one-way latency of the largest STANAG frame between two processes, without and with a CPU hog per CPU, default scheduling and real-time settings",
        "transport": transport.arg(),
        "frames": frames,
        "warmup": warmup,
        "payload_bytes": MAX_FRAME_LEN,
        "fifo_priority": LOAD_FIFO_PRIORITY,
        "sender_cpu_realtime": sender_cpu,
        "receiver_cpu_realtime": receiver_cpu,
        "load_average_before": load_before,
        "load_average_after": load_after,
        "goal_p999_us": LOAD_GOAL_P999.as_secs_f64() * 1e6,
        "results": results,
    });
    let path = write_output(
        "load.json",
        &serde_json::to_string_pretty(&document).expect("JSON"),
    );
    println!("Results: {}", path.display());
}

pub(super) fn print_load_table(results: &[Value]) {
    println!();
    let rows: Vec<&Value> = results.iter().collect();
    let reference = results.iter().find(|r| r["case"] == "load-default");
    print_rows("case", "case_label", &rows, reference, "load");
    println!(
        "(µs; p50/load and p99.9/load: ratio to CPU hogs with default scheduling; preempt: \
         involuntary context switches of sender/receiver while measuring; others: CPU time used \
         by other processes meanwhile, the hogs included, in % of all CPUs)"
    );
    for r in results.iter().filter(|r| !r["sender_realtime"].is_null()) {
        for side in ["sender", "receiver"] {
            let got = &r[format!("{side}_realtime")];
            println!(
                "{side} with real-time settings: {}{}",
                got["got"].as_str().unwrap_or("unknown"),
                match got["warnings"].as_array() {
                    Some(warnings) if !warnings.is_empty() => format!(
                        "; NOT GRANTED IN FULL: {}",
                        warnings
                            .iter()
                            .filter_map(Value::as_str)
                            .collect::<Vec<_>>()
                            .join("; ")
                    ),
                    _ => String::new(),
                }
            );
        }
    }
    if let Some(r) = results.iter().find(|r| r["case"] == "load-realtime") {
        let p999 = us(r, "p999_ns");
        let goal = LOAD_GOAL_P999.as_secs_f64() * 1e6;
        println!(
            "Goal (BENCHMARKS.md section 7): under load with real-time settings p99.9 at most \
             {goal:.0} µs: {p999:.2} µs, {}",
            if p999 <= goal { "met" } else { "NOT met" }
        );
    }
}

//! The environment recorded with every results directory (`env.json`): CPU model and flags,
//! cores, memory, OS, rustc, commit, Embree version.

use rtbench_reports::Environment;

/// UTC time as RFC 3339 to the second (`2026-11-21T09:30:00Z`), as every stored timestamp is.
pub fn now_utc() -> String {
    let now = time::OffsetDateTime::now_utc();
    now.replace_nanosecond(0)
        .unwrap_or(now)
        .format(&time::format_description::well_known::Rfc3339)
        .unwrap_or_default()
}

fn cpu_flags() -> Vec<String> {
    let text = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
    text.lines()
        .find(|l| l.starts_with("flags"))
        .and_then(|l| l.split_once(':'))
        .map(|(_, f)| f.split_whitespace().map(String::from).collect())
        .unwrap_or_default()
}

pub fn capture() -> Environment {
    let mut sys = sysinfo::System::new();
    sys.refresh_cpu_all();
    sys.refresh_memory();
    let cpu_model = sys
        .cpus()
        .first()
        .map(|c| c.brand().trim().to_string())
        .unwrap_or_default();
    Environment {
        cpu_model,
        cpu_flags: cpu_flags(),
        cores_logical: sys.cpus().len(),
        cores_physical: sys.physical_core_count(),
        memory_bytes: sys.total_memory(),
        os: sysinfo::System::long_os_version().unwrap_or_default(),
        kernel: sysinfo::System::kernel_version().unwrap_or_default(),
        hostname: sysinfo::System::host_name().unwrap_or_default(),
        rustc: env!("RTBENCH_RUSTC").to_string(),
        git_commit: env!("RTBENCH_GIT_COMMIT").to_string(),
        git_dirty: env!("RTBENCH_GIT_DIRTY") == "true",
        embree_version: rtbench_engines::embree::version().ok(),
        rtbench_version: env!("CARGO_PKG_VERSION").to_string(),
        started_at: now_utc(),
    }
}

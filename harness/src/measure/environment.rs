//! The environment recorded with every results directory (`env.json`): CPU model and flags,
//! cores, memory, OS, rustc, commit, Embree version.

use rtbench_reports::Environment;
use std::time::{SystemTime, UNIX_EPOCH};

/// UTC time as RFC 3339 (`2026-11-21T09:30:00Z`), without a date crate.
pub fn now_utc() -> String {
    let secs = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| d.as_secs() as i64)
        .unwrap_or(0);
    let (days, rem) = (secs.div_euclid(86400), secs.rem_euclid(86400));
    // Howard Hinnant's civil_from_days.
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!(
        "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}Z",
        rem / 3600,
        rem % 3600 / 60,
        rem % 60
    )
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

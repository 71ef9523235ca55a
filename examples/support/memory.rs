//! The process's peak memory, as the cost examples (`grid_cost`, `observer_cost`) report
//! it.

/// Peak resident memory of the process (bytes), from `/proc/self/status`'s `VmHWM`
/// (Linux; `None` elsewhere).
pub fn peak_memory() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024.0)
}

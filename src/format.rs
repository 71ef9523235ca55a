//! The byte and second formatters of the crate's messages and of the program's `info`
//! (the one copy: the program compiles this file into itself with `#[path]`, so the
//! library's public API does not grow by two formatting functions). It imports nothing.

/// `bytes` in kB, MB, GB or TB (decimal), three significant digits.
pub(crate) fn format_bytes(bytes: f64) -> String {
    const UNITS: [(f64, &str); 4] = [(1e12, "TB"), (1e9, "GB"), (1e6, "MB"), (1e3, "kB")];
    if bytes >= 1e15 {
        return format!("{bytes:.3e} B");
    }
    for (scale, unit) in UNITS {
        if bytes >= scale {
            return format!("{:.3} {unit}", bytes / scale);
        }
    }
    format!("{bytes:.0} B")
}

/// `seconds` in s, min, h or days, three significant digits.
pub(crate) fn format_seconds(seconds: f64) -> String {
    const UNITS: [(f64, &str); 3] = [(86400.0, "days"), (3600.0, "h"), (60.0, "min")];
    if seconds >= 1e3 * 86400.0 {
        return format!("{seconds:.3e} s");
    }
    for (scale, unit) in UNITS {
        if seconds >= scale {
            return format!("{:.3} {unit}", seconds / scale);
        }
    }
    format!("{seconds:.3} s")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units() {
        assert_eq!(format_bytes(2.4e10), "24.000 GB");
        assert_eq!(format_bytes(512.0), "512 B");
        assert_eq!(format_seconds(2600.0), "43.333 min");
        assert_eq!(format_seconds(0.25), "0.250 s");
        assert_eq!(format_bytes(2.4e20), "2.400e20 B");
        assert_eq!(format_seconds(1e9), "1.000e9 s");
    }
}

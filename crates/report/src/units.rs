//! Readable quantities: times in µs, ms or s, energies in µJ, mJ or J, counts in K or M,
//! each with about three significant digits, for tables, chart axes and the command line.

/// Three significant digits, at least none after the point for values ≥ 100.
fn sig3(v: f64) -> String {
    let a = v.abs();
    if !v.is_finite() {
        format!("{v}")
    } else if a >= 100.0 || a == 0.0 {
        format!("{v:.0}")
    } else if a >= 10.0 {
        format!("{v:.1}")
    } else if a >= 1.0 {
        format!("{v:.2}")
    } else {
        format!("{v:.3}")
    }
}

/// A time given in milliseconds: `850 µs`, `12.3 ms`, `1.52 s`.
pub fn time_ms(ms: f64) -> String {
    let a = ms.abs();
    if a != 0.0 && a < 1.0 {
        format!("{} µs", sig3(ms * 1e3))
    } else if a >= 1000.0 {
        format!("{} s", sig3(ms / 1e3))
    } else {
        format!("{} ms", sig3(ms))
    }
}

/// An energy given in joules: `850 µJ`, `12.3 mJ`, `1.52 J`.
pub fn energy_j(j: f64) -> String {
    let a = j.abs();
    if a != 0.0 && a < 1e-3 {
        format!("{} µJ", sig3(j * 1e6))
    } else if a != 0.0 && a < 1.0 {
        format!("{} mJ", sig3(j * 1e3))
    } else {
        format!("{} J", sig3(j))
    }
}

/// A count: `850`, `12.3K`, `4.56M`.
pub fn count(n: f64) -> String {
    let a = n.abs();
    if a >= 1e6 {
        format!("{}M", sig3(n / 1e6))
    } else if a >= 1e3 {
        format!("{}K", sig3(n / 1e3))
    } else {
        format!("{n:.0}")
    }
}

/// An axis tick: at most three decimals, trailing zeros dropped, thousands as K and
/// millions as M (`80000` → `80K`, `0.25` → `0.25`).
pub fn compact(v: f64) -> String {
    let trim = |x: f64| {
        let s = format!("{x:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    };
    let a = v.abs();
    if a >= 1e6 {
        format!("{}M", trim(v / 1e6))
    } else if a >= 1e3 {
        format!("{}K", trim(v / 1e3))
    } else {
        trim(v)
    }
}

/// The unit and scale that show every value of `values` (ms) as a number of about three
/// digits: `("µs", 1e3)` when all are below a millisecond, `("s", 1e-3)` when all are at
/// least a second, else `("ms", 1.0)`. For chart axes and table columns, which need one unit.
pub fn time_unit(values_ms: &[f64]) -> (&'static str, f64) {
    let max = values_ms.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if max > 0.0 && max < 1.0 {
        ("µs", 1e3)
    } else if max >= 1000.0 {
        ("s", 1e-3)
    } else {
        ("ms", 1.0)
    }
}

/// Like [`time_unit`] for energies given in joules: µJ, mJ or J.
pub fn energy_unit(values_j: &[f64]) -> (&'static str, f64) {
    let max = values_j.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if max > 0.0 && max < 1e-3 {
        ("µJ", 1e6)
    } else if max > 0.0 && max < 1.0 {
        ("mJ", 1e3)
    } else {
        ("J", 1.0)
    }
}

/// Like [`time_unit`] for counts: none, K (thousands) or M (millions).
pub fn count_unit(values: &[f64]) -> (&'static str, f64) {
    let max = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if max >= 1e6 {
        ("M", 1e-6)
    } else if max >= 1e4 {
        ("K", 1e-3)
    } else {
        ("", 1.0)
    }
}

/// Like [`time_unit`] for sizes given in bytes: KiB when all are below a MiB, else MiB.
pub fn bytes_unit(values: &[f64]) -> (&'static str, f64) {
    let max = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if max < 1024.0 * 1024.0 {
        ("KiB", 1.0 / 1024.0)
    } else {
        ("MiB", 1.0 / (1024.0 * 1024.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantities_read_in_the_right_unit() {
        assert_eq!(time_ms(0.00889), "8.89 µs");
        assert_eq!(time_ms(0.5), "500 µs");
        assert_eq!(time_ms(12.34), "12.3 ms");
        assert_eq!(time_ms(1520.0), "1.52 s");
        assert_eq!(energy_j(0.00889), "8.89 mJ");
        assert_eq!(energy_j(2.5e-5), "25.0 µJ");
        assert_eq!(energy_j(1.5), "1.50 J");
        assert_eq!(count(850.0), "850");
        assert_eq!(count(12_345.0), "12.3K");
        assert_eq!(count(4_560_000.0), "4.56M");
        assert_eq!(compact(80_000.0), "80K");
        assert_eq!(compact(1_250_000.0), "1.25M");
        assert_eq!(compact(0.25), "0.25");
        assert_eq!(compact(120.0), "120");
        assert_eq!(time_unit(&[0.2, 0.9]), ("µs", 1e3));
        assert_eq!(time_unit(&[0.2, 9.0]), ("ms", 1.0));
        assert_eq!(energy_unit(&[0.02, 0.5]), ("mJ", 1e3));
        assert_eq!(count_unit(&[2e6, 3e5]), ("M", 1e-6));
        assert_eq!(count_unit(&[2e4, 3e3]), ("K", 1e-3));
        assert_eq!(bytes_unit(&[2048.0]), ("KiB", 1.0 / 1024.0));
        assert_eq!(bytes_unit(&[3e6, 2048.0]).0, "MiB");
    }
}

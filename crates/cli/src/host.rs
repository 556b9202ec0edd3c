//! The machine a timing ran on, as `bench` records it beside its figures: ratios to Embree
//! depend on the CPU as much as on our code (`docs/performance.md`, "Machine and method").

use serde::Serialize;

/// The CPU and the instruction-set features that decide which kernels run (ours use AVX2
/// where present; Embree picks AVX-512 where present, else AVX2).
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Host {
    /// The CPU's name (`model name` in `/proc/cpuinfo`), or `unknown`.
    pub cpu: String,
    /// CPU family and model numbers where the OS gives them: they tell generations apart
    /// where the name does not (AMD family 25: model 1 is Zen 3, model 17 Zen 4).
    pub family: Option<u32>,
    pub model: Option<u32>,
    /// Logical CPUs the OS offers.
    pub cpus: usize,
    /// AVX2 present.
    pub avx2: bool,
    /// AVX-512 Foundation present.
    pub avx512f: bool,
}

impl Host {
    /// This machine.
    pub fn detect() -> Self {
        let info = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
        #[cfg(target_arch = "x86_64")]
        let (avx2, avx512f) = (
            std::is_x86_feature_detected!("avx2"),
            std::is_x86_feature_detected!("avx512f"),
        );
        #[cfg(not(target_arch = "x86_64"))]
        let (avx2, avx512f) = (false, false);
        Self::from_cpuinfo(
            &info,
            std::thread::available_parallelism().map_or(1, |n| n.get()),
            avx2,
            avx512f,
        )
    }

    /// The host `/proc/cpuinfo`'s text `info` describes (its first processor's fields).
    fn from_cpuinfo(info: &str, cpus: usize, avx2: bool, avx512f: bool) -> Self {
        let field = |name: &str| {
            info.lines().find_map(|l| {
                let (k, v) = l.split_once(':')?;
                (k.trim() == name).then(|| v.trim().to_string())
            })
        };
        Self {
            cpu: field("model name").unwrap_or_else(|| "unknown".into()),
            family: field("cpu family").and_then(|v| v.parse().ok()),
            model: field("model").and_then(|v| v.parse().ok()),
            cpus,
            avx2,
            avx512f,
        }
    }
}

impl std::fmt::Display for Host {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.cpu)?;
        if let (Some(fam), Some(m)) = (self.family, self.model) {
            write!(f, " (family {fam}, model {m})")?;
        }
        let yes = |b: bool| if b { "" } else { "no " };
        write!(
            f,
            ", {} CPUs, {}AVX2, {}AVX-512",
            self.cpus,
            yes(self.avx2),
            yes(self.avx512f)
        )
    }
}

#[cfg(test)]
mod tests {
    use super::Host;

    #[test]
    fn reads_the_first_processor_of_cpuinfo() {
        let info = "processor\t: 0\nvendor_id\t: AuthenticAMD\ncpu family\t: 25\n\
                    model\t\t: 1\nmodel name\t: AMD EPYC\n\nprocessor\t: 1\ncpu family\t: 6\n";
        let h = Host::from_cpuinfo(info, 2, true, false);
        assert_eq!(h.cpu, "AMD EPYC");
        assert_eq!((h.family, h.model), (Some(25), Some(1)));
        assert_eq!(
            h.to_string(),
            "AMD EPYC (family 25, model 1), 2 CPUs, AVX2, no AVX-512"
        );
    }

    #[test]
    fn without_cpuinfo_the_cpu_is_unknown() {
        let h = Host::from_cpuinfo("", 1, false, false);
        assert_eq!(h.cpu, "unknown");
        assert_eq!((h.family, h.model), (None, None));
        assert_eq!(h.to_string(), "unknown, 1 CPUs, no AVX2, no AVX-512");
    }
}

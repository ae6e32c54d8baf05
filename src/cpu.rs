//! The CPU features this build was compiled to assume, checked against the CPU it runs on.
//!
//! Builds from this repository target x86-64-v3 (`.cargo/config.toml` says why). Such a binary
//! would die of an illegal instruction on an older CPU; [`missing`] lets the command line say
//! instead, in words, what the CPU lacks and how to build for it.

/// The instruction-set features this build assumes that the running CPU lacks (empty when the
/// CPU has them all, and on a build that assumes none of them).
pub fn missing() -> Vec<&'static str> {
    #[cfg(target_arch = "x86_64")]
    {
        missing_with(detected)
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        Vec::new()
    }
}

/// The features of [`ASSUMED`] that this build was compiled with and `has` says are absent.
fn missing_with(has: impl Fn(&str) -> bool) -> Vec<&'static str> {
    ASSUMED
        .iter()
        .filter(|(_, compiled)| *compiled)
        .map(|&(name, _)| name)
        .filter(|name| !has(name))
        .collect()
}

/// [`ASSUMED`] and the run-time check of each of its features, from one list.
macro_rules! features {
    ($($name:tt),*) => {
        /// The x86-64-v2 and -v3 features, each with whether this build was compiled to use it.
        const ASSUMED: &[(&str, bool)] = &[$(($name, cfg!(target_feature = $name))),*];

        /// Whether the running CPU has feature `name` (one of [`ASSUMED`]'s).
        #[cfg(target_arch = "x86_64")]
        fn detected(name: &str) -> bool {
            match name {
                $($name => std::arch::is_x86_feature_detected!($name),)*
                _ => false,
            }
        }
    };
}

features!(
    "sse3", "ssse3", "sse4.1", "sse4.2", "popcnt", "avx", "avx2", "bmi1", "bmi2", "fma", "lzcnt",
    "movbe", "f16c"
);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cpu_without_the_features_is_told_which_the_build_assumes() {
        // A CPU with nothing: every feature the build was compiled with is named, and only those.
        let all = missing_with(|_| false);
        let compiled: Vec<&str> = ASSUMED.iter().filter(|f| f.1).map(|f| f.0).collect();
        assert_eq!(all, compiled);
        // A CPU with everything, and this one (which runs the test): nothing is missing.
        assert!(missing_with(|_| true).is_empty());
        assert!(missing().is_empty(), "{:?}", missing());
    }
}

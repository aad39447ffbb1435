//! The worker threads of a program's run: `--jobs`, Python's `jobs=`, or `RAYON_NUM_THREADS`.
//!
//! rayon reads `RAYON_NUM_THREADS` (else `RAYON_RS_NUM_CPUS`) at its first parallel call,
//! starts as many threads as it asks for without a bound, and panics there, and at every later
//! parallel call, when the system refuses them. A program (the command line, the Python
//! package) starts the pool itself with [`start_workers`], so that a count out of range is a
//! warning and a refusal one error, before any work is done.

use crate::PipelineError;

/// The most worker threads a run takes (`ridi --jobs`, Python's `jobs=`, `RAYON_NUM_THREADS`):
/// beyond the cores they add no speed, and each holds a stack.
pub const MAX_JOBS: usize = 4096;

/// The variables rayon reads for its count, in its order.
const VARIABLES: [&str; 2] = ["RAYON_NUM_THREADS", "RAYON_RS_NUM_CPUS"];

/// The worker threads of a run, as [`start_workers`] left them.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Workers {
    /// How many: those started, or, where nothing asked for a count, the one per core that
    /// rayon starts at its first parallel call.
    pub threads: usize,
    /// A variable that asked for no count from 1 to [`MAX_JOBS`] (one thread per core
    /// instead), in words.
    pub warning: Option<String>,
}

/// The worker threads the variable `name`, set to `text`, asks for on a machine of `cores`,
/// and a warning where it asks for no count from 1 to [`MAX_JOBS`]: then one per core. `0`
/// asks for one per core, as rayon reads it.
fn env_jobs(name: &str, text: &str, cores: usize) -> (usize, Option<String>) {
    let warning = |what: &str| {
        Some(format!(
            "{name}={} {what}: using one worker thread per core ({cores})",
            crate::data::shown(text)
        ))
    };
    match text.trim().parse::<u128>() {
        Ok(0) => (cores, None),
        Ok(n) if n <= MAX_JOBS as u128 => (n as usize, None),
        Ok(_) => (cores, warning(&format!("is over {MAX_JOBS} threads"))),
        Err(_) => (cores, warning("is not a whole number")),
    }
}

/// Starts rayon's global pool for the rest of the run: `jobs` threads, else the count the
/// first of `RAYON_NUM_THREADS` and `RAYON_RS_NUM_CPUS` that is set (and not blank) asks for.
/// With neither, nothing is started here: rayon starts one thread per core at its first
/// parallel call. A variable that asks for no count from 1 to [`MAX_JOBS`] gets one thread per
/// core and a warning ([`Workers::warning`]); `jobs` outranks the variables. Callers check
/// `jobs` (1 to [`MAX_JOBS`], as `--jobs` is); a value outside is taken as the nearest bound.
///
/// # Errors
/// [`PipelineError::Workers`] when the system refuses the threads (a process or memory limit),
/// or when the global pool is already running: this is for a program's start, once.
pub fn start_workers(jobs: Option<usize>) -> Result<Workers, PipelineError> {
    let cores = std::thread::available_parallelism().map_or(1, usize::from);
    let set = VARIABLES.iter().find_map(|&name| {
        let text = std::env::var_os(name)?.to_string_lossy().into_owned();
        (!text.trim().is_empty()).then_some((name, text))
    });
    let (threads, variable, warning) = match (jobs, set) {
        (Some(n), _) => (n.clamp(1, MAX_JOBS), None, None),
        (None, Some((name, text))) => {
            let (threads, warning) = env_jobs(name, &text, cores);
            (
                threads,
                Some(format!("{name}={}", crate::data::shown(&text))),
                warning,
            )
        }
        (None, None) => {
            return Ok(Workers {
                threads: cores,
                warning: None,
            });
        }
    };
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build_global()
        .map_err(|e| PipelineError::Workers {
            threads,
            variable,
            reason: e.to_string(),
        })?;
    Ok(Workers { threads, warning })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_variable_beyond_the_limit_or_not_a_count_is_one_thread_per_core() {
        let jobs = |text| env_jobs("RAYON_NUM_THREADS", text, 2);
        assert_eq!(jobs("3"), (3, None));
        assert_eq!(jobs(" 4096 "), (4096, None));
        assert_eq!(jobs("0"), (2, None));
        let (n, warning) = jobs("100000");
        assert_eq!(n, 2);
        assert_eq!(
            warning.unwrap(),
            "RAYON_NUM_THREADS=100000 is over 4096 threads: using one worker thread per core (2)"
        );
        let (n, warning) = jobs("99999999999999999999999999999999999999999");
        assert_eq!((n, warning.is_some()), (2, true));
        let (n, warning) = env_jobs("RAYON_RS_NUM_CPUS", "2x", 8);
        assert_eq!(n, 8);
        assert_eq!(
            warning.unwrap(),
            "RAYON_RS_NUM_CPUS=2x is not a whole number: using one worker thread per core (8)"
        );
    }
}

//! The worker threads of a program's run: `--jobs`, Python's `jobs=`, or `RAYON_NUM_THREADS`.
//!
//! rayon reads `RAYON_NUM_THREADS` at its first parallel call, starts as many threads as it
//! asks for without a bound, and panics there when the system refuses them. A program (the
//! command line, the Python package) starts the pool itself with [`start_workers`], so that a
//! count out of range is a warning and a refusal one line of error, before any work is done.

use crate::PipelineError;

/// The most worker threads a run takes (`ridi --jobs`, Python's `jobs=`, `RAYON_NUM_THREADS`):
/// beyond the cores they add no speed, and each holds a stack.
pub const MAX_JOBS: usize = 4096;

/// The worker threads `RAYON_NUM_THREADS` (its value `text`) asks for on a machine of `cores`,
/// and a warning where it asks for no count from 1 to [`MAX_JOBS`]: then one per core. `0`
/// asks for one per core, as rayon reads it.
fn env_jobs(text: &str, cores: usize) -> (usize, Option<String>) {
    let warning = |what: &str| {
        Some(format!(
            "RAYON_NUM_THREADS={} {what}: using one worker thread per core ({cores})",
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

/// Starts rayon's global pool for the rest of the run: `jobs` threads (1 to [`MAX_JOBS`]), else
/// the count `RAYON_NUM_THREADS` asks for when it is set. With neither, nothing is started
/// here: rayon starts one thread per core at its first parallel call. Returns a warning for a
/// `RAYON_NUM_THREADS` that asks for no count from 1 to [`MAX_JOBS`] (one thread per core is
/// started instead); `jobs` outranks the variable.
///
/// # Errors
/// [`PipelineError::Workers`] when the system refuses the threads, or when the global pool is
/// already running (this is for a program's start, once).
pub fn start_workers(jobs: Option<usize>) -> Result<Option<String>, PipelineError> {
    let (threads, warning) = match jobs {
        Some(n) => (n.clamp(1, MAX_JOBS), None),
        None => match std::env::var_os("RAYON_NUM_THREADS") {
            None => return Ok(None),
            Some(text) => {
                let cores = std::thread::available_parallelism().map_or(1, usize::from);
                env_jobs(&text.to_string_lossy(), cores)
            }
        },
    };
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build_global()
        .map_err(|e| PipelineError::Workers {
            threads,
            reason: e.to_string(),
        })?;
    Ok(warning)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rayon_num_threads_beyond_the_limit_or_not_a_count_is_one_thread_per_core() {
        assert_eq!(env_jobs("3", 2), (3, None));
        assert_eq!(env_jobs(" 4096 ", 2), (4096, None));
        assert_eq!(env_jobs("0", 2), (2, None));
        let (n, warning) = env_jobs("100000", 2);
        assert_eq!(n, 2);
        assert_eq!(
            warning.unwrap(),
            "RAYON_NUM_THREADS=100000 is over 4096 threads: using one worker thread per core (2)"
        );
        let (n, warning) = env_jobs("99999999999999999999999999999999999999999", 8);
        assert_eq!((n, warning.is_some()), (8, true));
        let (n, warning) = env_jobs("2x", 8);
        assert_eq!(n, 8);
        assert_eq!(
            warning.unwrap(),
            "RAYON_NUM_THREADS=2x is not a whole number: using one worker thread per core (8)"
        );
    }
}

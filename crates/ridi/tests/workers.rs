//! `ridi::start_workers` on its own process (rayon's global pool can be started once): a
//! second start is an error naming the count, not a panic.

#[test]
fn the_global_pool_starts_once_and_a_second_start_is_an_error() {
    let workers = ridi::start_workers(Some(2)).unwrap();
    assert_eq!(
        workers,
        ridi::Workers {
            threads: 2,
            warning: None
        }
    );
    assert_eq!(rayon::current_num_threads(), 2);
    let e = ridi::start_workers(Some(3)).unwrap_err();
    assert!(matches!(
        e,
        ridi::PipelineError::Workers {
            threads: 3,
            variable: None,
            ..
        }
    ));
    assert_eq!(
        e.to_string(),
        "cannot start 3 worker threads: The global thread pool has already been initialized."
    );
}

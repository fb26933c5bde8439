//! A fixed pool of worker threads over a list of jobs (std scoped threads, no dependency):
//! each worker takes the next job index from a shared counter, so long and short clips spread
//! over the workers without a plan; results come back to the calling thread in the order they
//! finish.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc;

/// Runs `work(i, &items[i])` for every item on `jobs` threads (at least 1, at most the
/// number of items) and calls `done(i, result)` on the calling thread as each finishes. A
/// job that panics gives `Err(message)` and the others go on.
pub fn run_parallel<T, R, W, D>(items: &[T], jobs: usize, work: W, mut done: D)
where
    T: Sync,
    R: Send,
    W: Fn(usize, &T) -> R + Sync,
    D: FnMut(usize, Result<R, String>),
{
    let next = AtomicUsize::new(0);
    let workers = jobs.clamp(1, items.len().max(1));
    let (tx, rx) = mpsc::channel();
    std::thread::scope(|scope| {
        for _ in 0..workers {
            let tx = tx.clone();
            let (next, work) = (&next, &work);
            scope.spawn(move || loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                let Some(item) = items.get(i) else { break };
                let r = catch_unwind(AssertUnwindSafe(|| work(i, item))).map_err(|p| {
                    p.downcast_ref::<&str>()
                        .map(|s| s.to_string())
                        .or_else(|| p.downcast_ref::<String>().cloned())
                        .unwrap_or_else(|| "a worker panicked".into())
                });
                if tx.send((i, r)).is_err() {
                    break;
                }
            });
        }
        drop(tx);
        for (i, r) in rx {
            done(i, r);
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_job_runs_once_and_a_panic_is_reported() {
        let items: Vec<usize> = (0..50).collect();
        let mut seen = vec![0usize; items.len()];
        let mut panics = 0;
        run_parallel(
            &items,
            3,
            |i, x| {
                assert!(*x != 17, "job seventeen");
                i * 2
            },
            |i, r| match r {
                Ok(v) => {
                    assert_eq!(v, 2 * i);
                    seen[i] += 1
                }
                Err(m) => {
                    assert!(m.contains("seventeen"), "{m}");
                    panics += 1;
                    seen[i] += 1
                }
            },
        );
        assert_eq!(panics, 1);
        assert!(seen.iter().all(|c| *c == 1), "{seen:?}");
    }
}

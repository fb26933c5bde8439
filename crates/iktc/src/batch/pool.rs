//! A fixed pool of worker threads over a list of jobs, on a [`rayon`] thread pool of its own
//! (the user's job count, not rayon's global pool): the jobs are queued in a given order and
//! each idle worker takes the next, so long and short clips spread over the workers without a
//! plan; results come back to the calling thread in the order they finish.
//!
//! The order the jobs are taken in matters when one job is a large share of the batch: taken
//! last, it runs alone while the other workers idle. [`longest_first`] orders jobs by an
//! estimate of their cost, largest first (Graham's LPT rule: the batch then takes at most
//! 4/3 of the shortest possible time on any number of workers, against up to twice for an
//! arbitrary order).

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;

/// Runs `work(i, &items[i])` for every item on `jobs` threads (at least 1, at most the
/// number of items), taken in the items' order, and calls `done(i, result)` on the calling
/// thread as each finishes. A job that panics gives `Err(message)` and the others go on.
pub fn run_parallel<T, R, W, D>(items: &[T], jobs: usize, work: W, done: D)
where
    T: Sync,
    R: Send,
    W: Fn(usize, &T) -> R + Sync,
    D: FnMut(usize, Result<R, String>),
{
    let order: Vec<usize> = (0..items.len()).collect();
    run_parallel_in(items, &order, jobs, work, done);
}

/// The indices of `items` by decreasing `cost` (any unit, e.g. the bytes of a clip's file as
/// an estimate of its duration), equal costs in the items' order: the order for
/// [`run_parallel_in`].
pub fn longest_first<T>(items: &[T], cost: impl Fn(&T) -> u64) -> Vec<usize> {
    let mut order: Vec<usize> = (0..items.len()).collect();
    order.sort_by_key(|&i| std::cmp::Reverse(cost(&items[i])));
    order
}

/// As [`run_parallel`], the jobs taken in `order` (indices into `items`; each index at most
/// once, any index out of range skipped); `work` and `done` still receive the item's own index.
pub fn run_parallel_in<T, R, W, D>(items: &[T], order: &[usize], jobs: usize, work: W, done: D)
where
    T: Sync,
    R: Send,
    W: Fn(usize, &T) -> R + Sync,
    D: FnMut(usize, Result<R, String>),
{
    run_parallel_until(items, order, jobs, &AtomicBool::new(false), work, done);
}

/// As [`run_parallel_in`], no job taken once `stop` is set (e.g. by a signal handler): the
/// jobs running then finish and are reported, the jobs not yet taken are not run (nor
/// reported).
///
/// The jobs are spawned from the calling thread, outside the pool, into a rayon FIFO scope:
/// they enter the pool's queue in `order` and its workers take them from its front. Should
/// the pool's threads fail to start, the jobs run one after the other on the calling thread.
pub fn run_parallel_until<T, R, W, D>(
    items: &[T],
    order: &[usize],
    jobs: usize,
    stop: &AtomicBool,
    work: W,
    mut done: D,
) where
    T: Sync,
    R: Send,
    W: Fn(usize, &T) -> R + Sync,
    D: FnMut(usize, Result<R, String>),
{
    let workers = jobs.clamp(1, order.len().max(1));
    let job = |i: usize| -> Option<Result<R, String>> {
        if stop.load(Ordering::SeqCst) {
            return None;
        }
        let item = items.get(i)?;
        Some(catch_unwind(AssertUnwindSafe(|| work(i, item))).map_err(panic_message))
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(workers)
        .thread_name(|k| format!("iktc-batch-{k}"))
        .build();
    let Ok(pool) = pool else {
        for &i in order {
            if let Some(r) = job(i) {
                done(i, r);
            }
        }
        return;
    };
    let (tx, rx) = mpsc::channel();
    pool.in_place_scope_fifo(|scope| {
        for &i in order {
            let (tx, job) = (tx.clone(), &job);
            scope.spawn_fifo(move |_| {
                if let Some(r) = job(i) {
                    // The receiver lives until every job has ended.
                    let _ = tx.send((i, r));
                }
            });
        }
        drop(tx);
        for (i, r) in rx {
            done(i, r);
        }
    });
}

/// The message of a caught panic: its `&str` or `String` payload, or a generic one.
fn panic_message(p: Box<dyn std::any::Any + Send>) -> String {
    p.downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| p.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "a worker panicked".into())
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

    #[test]
    fn the_longest_jobs_are_taken_first() {
        let costs = [3u64, 9, 1, 9, 5];
        let order = longest_first(&costs, |c| *c);
        assert_eq!(order, vec![1, 3, 4, 0, 2]);
        // One worker takes them exactly in that order, and reports each under its own index.
        let taken = std::sync::Mutex::new(Vec::new());
        let mut reported = Vec::new();
        run_parallel_in(
            &costs,
            &order,
            1,
            |i, c| {
                taken.lock().unwrap().push(i);
                *c
            },
            |i, r| reported.push((i, r.unwrap())),
        );
        assert_eq!(*taken.lock().unwrap(), order);
        let expected: Vec<(usize, u64)> = order.iter().map(|&i| (i, costs[i])).collect();
        assert_eq!(reported, expected);
    }

    /// Graham's example of why the order matters: on two workers, jobs of cost 1, 1, 2 taken
    /// in that order end at 3 (the 2 starts after a 1), longest first at 2.
    #[test]
    fn longest_first_shortens_the_batch() {
        let costs = [1u64, 1, 2];
        let makespan = |order: &[usize]| {
            let mut free = [0u64; 2];
            for &i in order {
                let w = if free[0] <= free[1] { 0 } else { 1 };
                free[w] += costs[i];
            }
            free[0].max(free[1])
        };
        assert_eq!(makespan(&[0, 1, 2]), 3);
        assert_eq!(makespan(&longest_first(&costs, |c| *c)), 2);
    }

    /// A stop set by the third job: one worker runs jobs 0, 1 and 2 and takes no other.
    #[test]
    fn no_job_is_taken_after_the_stop() {
        let items: Vec<usize> = (0..10).collect();
        let order: Vec<usize> = (0..10).collect();
        let stop = AtomicBool::new(false);
        let mut reported = Vec::new();
        run_parallel_until(
            &items,
            &order,
            1,
            &stop,
            |i, _| {
                if i == 2 {
                    stop.store(true, Ordering::SeqCst);
                }
                i
            },
            |i, r| reported.push((i, r.unwrap())),
        );
        assert_eq!(reported, vec![(0, 0), (1, 1), (2, 2)]);
    }

    #[test]
    fn indices_out_of_range_are_skipped() {
        let items = [10u32, 20];
        let mut got = Vec::new();
        run_parallel_in(
            &items,
            &[5, 1, 0],
            2,
            |_, x| *x,
            |i, r| got.push((i, r.unwrap())),
        );
        got.sort();
        assert_eq!(got, vec![(0, 10), (1, 20)]);
    }
}

//! Independent jobs on one worker per core, the results in the jobs' order: the backend
//! slots of the cross-backend check and of the texture corpus (each its own device,
//! compiling its own pipelines: a CPU driver such as lavapipe compiles on one core per
//! pipeline), the kernels' validators (`xtask shaders`) and the programs run under the
//! validation layer (`xtask validate`), each mostly an external process on one core.

use std::sync::atomic::{AtomicUsize, Ordering};

/// `job(item)` for every item of `items`, on up to one thread per core (each takes the
/// next item when it is done with one); the results in `items`' order.
pub fn map<T: Sync, R: Send>(items: &[T], job: impl Fn(&T) -> R + Sync) -> Vec<R> {
    let next = AtomicUsize::new(0);
    let workers = std::thread::available_parallelism().map_or(1, |n| n.get()).min(items.len().max(1));
    let mut results: Vec<Option<R>> = (0..items.len()).map(|_| None).collect();
    std::thread::scope(|scope| {
        let handles: Vec<_> = (0..workers)
            .map(|_| {
                scope.spawn(|| {
                    let mut done = Vec::new();
                    loop {
                        let index = next.fetch_add(1, Ordering::Relaxed);
                        let Some(item) = items.get(index) else { return done };
                        done.push((index, job(item)));
                    }
                })
            })
            .collect();
        for handle in handles {
            for (index, result) in handle.join().expect("a worker panicked") {
                results[index] = Some(result);
            }
        }
    });
    results.into_iter().map(|result| result.expect("every item taken by a worker")).collect()
}

#[cfg(test)]
mod tests {
    #[test]
    fn results_come_in_the_items_order() {
        let items: Vec<u32> = (0..37).collect();
        assert_eq!(super::map(&items, |x| x * 2), items.iter().map(|x| x * 2).collect::<Vec<_>>());
        assert!(super::map(&[] as &[u32], |x| *x).is_empty());
    }
}

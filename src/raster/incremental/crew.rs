//! A crew of worker threads that stay awake between short parallel jobs: the image-driven
//! optimizer's trials (`trial.rs`) spread 20 views over the cores thousands of times a
//! second, and each trial takes a few hundred microseconds.
//!
//! Why not rayon here: between two trials rayon's workers go to sleep, and each trial wakes them
//! again (a futex wake, a context switch and the scheduler's latency, then `sched_yield` calls
//! while they look for work): about a tenth of the optimizer's CPU time went to the kernel.
//! A crew worker spins on an epoch counter for a while after each job (about a millisecond) and
//! only then sleeps on a condition variable, so back-to-back jobs find it awake.
//!
//! A job is `f(i)` for `i` in `0..n`; the calling thread takes part, and indices are claimed one
//! at a time (views differ a lot in work). The caller claims from the front, the workers from the
//! back: a caller that runs job after job over the same items keeps most items on the same
//! thread (all but those around where the two ends meet), so their data stays in that core's
//! cache. (Against claims from one end over a list sorted by the last trial's work, which moved
//! views between cores from trial to trial, an in-process A/B alternating every 64 trials on 2
//! threads gave 4-5 % less time in the optimizer's trials; an A/A of that partition later showed
//! 3.5-4.8 % of it to be the partition's bias, so the gain is about 0-1.5 %.) The caller gets
//! control back only
//! when every call has returned, which is what makes lending `f` (and what it borrows) to the
//! workers sound.

use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::thread::JoinHandle;

/// How long a worker looks for the next job before it sleeps.
const SPIN: std::time::Duration = std::time::Duration::from_millis(1);

/// The job: `f(i)` for `i < n`. `f` is lent by [`Crew::run`] for the duration of the call only;
/// the `'static` is a lie told to store it, made safe by `run` waiting for every call.
#[derive(Clone, Copy)]
struct Job {
    epoch: u32,
    n: u32,
    f: *const (dyn Fn(usize) + Sync + 'static),
}

// SAFETY: `f` is `Sync` and outlives every use (see `Crew::run`).
unsafe impl Send for Job {}

struct Inner {
    /// (epoch << 32) | (indices claimed from the back << 16) | indices claimed from the front.
    /// The epoch (the job's number) is bumped under `job`'s lock when a job is published;
    /// workers watch it for the next job.
    claim: AtomicU64,
    /// Calls of the current job that have returned.
    done: AtomicUsize,
    job: Mutex<Option<Job>>,
    wake: Condvar,
    stop: AtomicBool,
    /// A call panicked on a worker (the caller panics in turn once the job is done).
    panicked: AtomicBool,
    /// Workers asleep on `wake` (or about to be): a job is announced to them only then, since
    /// a notification costs a system call even when nobody waits.
    sleepers: AtomicUsize,
}

/// Worker threads for [`Crew::run`] (none for a crew of one: the caller does everything).
pub(crate) struct Crew {
    inner: Arc<Inner>,
    workers: Vec<JoinHandle<()>>,
}

impl std::fmt::Debug for Crew {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Crew({} threads)", self.workers.len() + 1)
    }
}

impl Crew {
    /// A crew of `threads` threads in all: the caller and `threads − 1` workers. (More than the
    /// machine has cores only slows it down: a spinning worker without a core of its own holds
    /// up the others.)
    pub fn new(threads: usize) -> Crew {
        let inner = Arc::new(Inner {
            claim: AtomicU64::new(0),
            done: AtomicUsize::new(0),
            job: Mutex::new(None),
            wake: Condvar::new(),
            stop: AtomicBool::new(false),
            panicked: AtomicBool::new(false),
            sleepers: AtomicUsize::new(0),
        });
        let workers = (1..threads.max(1))
            .map(|k| {
                let inner = inner.clone();
                std::thread::Builder::new()
                    .name(format!("lodeval-crew-{k}"))
                    .spawn(move || work(&inner))
                    .expect("spawn a crew thread")
            })
            .collect();
        Crew { inner, workers }
    }

    /// Call `f(i)` for every `i` in `0..n` (at most [`MAX_JOB`]), spread over the crew; returns
    /// when all calls have.
    pub fn run(&self, n: usize, f: &(dyn Fn(usize) + Sync)) {
        assert!(n <= MAX_JOB, "a crew job of {n} calls");
        if self.workers.is_empty() || n <= 1 {
            (0..n).for_each(f);
            return;
        }
        let inner = &*self.inner;
        // SAFETY: only the lifetime is erased. No worker calls `f` after this function returns:
        // a call needs an index claimed under this job's epoch, and we return only when all `n`
        // claimed calls have returned (`done == n`); later claims of this epoch find `n` taken.
        let f: *const (dyn Fn(usize) + Sync + 'static) = unsafe { std::mem::transmute(f) };
        let job = Job {
            epoch: epoch_of(inner.claim.load(Ordering::Relaxed)).wrapping_add(1),
            n: n as u32,
            f,
        };
        // The job is in place before its epoch shows, and the lock is free by then: a
        // spinning worker that sees the epoch takes the lock without waiting for it.
        *inner.job.lock().expect("crew lock") = Some(job);
        inner.done.store(0, Ordering::Relaxed);
        inner
            .claim
            .store((job.epoch as u64) << 32, Ordering::SeqCst);
        // A worker counts itself asleep before it looks at the epoch a last time (both
        // sequentially consistent): either it sees this epoch and stays up, or it is counted
        // here, and the notification under the lock reaches it once it waits.
        if inner.sleepers.load(Ordering::SeqCst) > 0 {
            let _job = inner.job.lock().expect("crew lock");
            inner.wake.notify_all();
        }
        take_part(inner, job, End::Front);
        while inner.done.load(Ordering::Acquire) < n {
            std::hint::spin_loop();
        }
        if inner.panicked.swap(false, Ordering::AcqRel) {
            panic!("a crew worker panicked");
        }
    }
}

impl Drop for Crew {
    fn drop(&mut self) {
        {
            let _job = self.inner.job.lock().expect("crew lock");
            self.inner.stop.store(true, Ordering::Release);
            self.inner.wake.notify_all();
        }
        for w in self.workers.drain(..) {
            let _ = w.join();
        }
    }
}

/// Calls per job: each end's count has 16 bits of the claim word.
const MAX_JOB: usize = 0xffff;

/// The end of the index range a thread claims from.
#[derive(Clone, Copy)]
enum End {
    Front,
    Back,
}

/// Claim indices of `job` from `end` and call its function until none are left.
fn take_part(inner: &Inner, job: Job, end: End) {
    let mut c = inner.claim.load(Ordering::Acquire);
    loop {
        let (front, back) = (c as u32 & 0xffff, (c as u32) >> 16);
        if epoch_of(c) != job.epoch || front + back >= job.n {
            return;
        }
        let (next, index) = match end {
            End::Front => (c + 1, front),
            End::Back => (c + (1 << 16), job.n - 1 - back),
        };
        match inner
            .claim
            .compare_exchange_weak(c, next, Ordering::AcqRel, Ordering::Acquire)
        {
            Ok(_) => {
                // SAFETY: the index was claimed under the job's epoch, so `run` is still waiting
                // for this call (see there).
                let call = || unsafe { (*job.f)(index as usize) };
                if std::panic::catch_unwind(std::panic::AssertUnwindSafe(call)).is_err() {
                    inner.panicked.store(true, Ordering::Release);
                }
                inner.done.fetch_add(1, Ordering::Release);
                c = inner.claim.load(Ordering::Acquire);
            }
            Err(now) => c = now,
        }
    }
}

/// The epoch part of a claim word.
fn epoch_of(claim: u64) -> u32 {
    (claim >> 32) as u32
}

/// A worker's life: spin for the next job, sleep when none comes for a while.
fn work(inner: &Inner) {
    let mut seen = 0u32;
    let waiting = |seen: u32| {
        epoch_of(inner.claim.load(Ordering::SeqCst)) == seen && !inner.stop.load(Ordering::Acquire)
    };
    loop {
        let (mut spins, start) = (0u32, std::time::Instant::now());
        while waiting(seen) {
            spins = spins.wrapping_add(1);
            if spins % 64 != 0 || start.elapsed() < SPIN {
                std::hint::spin_loop();
                continue;
            }
            let job = inner.job.lock().expect("crew lock");
            inner.sleepers.fetch_add(1, Ordering::SeqCst);
            let _job = inner
                .wake
                .wait_while(job, |_| waiting(seen))
                .expect("crew lock");
            inner.sleepers.fetch_sub(1, Ordering::SeqCst);
            break;
        }
        if inner.stop.load(Ordering::Acquire) {
            return;
        }
        let job = inner
            .job
            .lock()
            .expect("crew lock")
            .expect("a published job");
        seen = job.epoch;
        take_part(inner, job, End::Back);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_index_runs_once_per_job_for_any_crew_size() {
        for threads in [1, 2, 3, 8] {
            let crew = Crew::new(threads);
            for round in 0..300usize {
                let n = round % 23;
                let hits: Vec<AtomicUsize> = (0..n).map(|_| AtomicUsize::new(0)).collect();
                let sum = AtomicU64::new(0);
                crew.run(n, &|i| {
                    hits[i].fetch_add(1, Ordering::Relaxed);
                    sum.fetch_add((i * round) as u64, Ordering::Relaxed);
                });
                assert!(hits.iter().all(|h| h.load(Ordering::Relaxed) == 1));
                assert_eq!(
                    sum.into_inner(),
                    (n * n.saturating_sub(1) / 2 * round) as u64
                );
            }
        }
    }

    #[test]
    fn the_caller_takes_a_prefix_and_the_worker_the_rest() {
        // What keeps an item on one thread from job to job: the caller claims from the front and
        // the worker from the back, so the caller's items are 0..k and the worker's k..n,
        // however their claims interleave in time.
        let crew = Crew::new(2);
        let caller = std::thread::current().id();
        for round in 0..300usize {
            let n = 2 + round % 21;
            let by_caller: Vec<AtomicBool> = (0..n).map(|_| AtomicBool::new(false)).collect();
            crew.run(n, &|i| {
                by_caller[i].store(std::thread::current().id() == caller, Ordering::Relaxed);
                // Some work, so that the worker gets to claim too.
                for j in 0..2000 * (i % 3 + 1) {
                    std::hint::black_box(j);
                }
            });
            let flags: Vec<bool> = by_caller
                .iter()
                .map(|b| b.load(Ordering::Relaxed))
                .collect();
            let k = flags.iter().take_while(|&&c| c).count();
            assert!(
                flags[k..].iter().all(|&c| !c),
                "round {round}: caller's items {flags:?} are not a prefix"
            );
        }
    }

    #[test]
    fn sleeping_workers_wake_for_the_next_job() {
        let crew = Crew::new(2);
        let count = AtomicUsize::new(0);
        crew.run(4, &|_| {
            count.fetch_add(1, Ordering::Relaxed);
        });
        // Long enough for the worker to stop spinning and sleep.
        std::thread::sleep(std::time::Duration::from_millis(50));
        crew.run(4, &|_| {
            count.fetch_add(1, Ordering::Relaxed);
        });
        assert_eq!(count.into_inner(), 8);
    }
}

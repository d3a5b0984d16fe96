//! Wider vector instructions for the hot loops, where the processor has them.
//!
//! The release build targets baseline x86-64 (SSE2: two doubles per instruction), so that the
//! binary runs on any x86-64 machine. The passes over the observations spend most of their time
//! in elementwise loops (the Gram updates `A += w J^T J`, the Newton rank-one terms), which AVX
//! runs four doubles at a time. [`with_avx`] runs a closure compiled for AVX when the processor
//! has it (a cached run-time check). The results are the same bits either way: Rust never fuses
//! a multiply and an add on its own, nor reorders a sum, so only the width of the instructions
//! changes (tested: a pass gives the same bits with and without).
//!
//! Written by hand rather than with a multiversioning crate: one dispatch point of a few lines.

/// Runs `f`, compiled for AVX where the processor has it (see the module docs).
#[inline(always)]
pub(crate) fn with_avx<R>(f: impl FnOnce() -> R) -> R {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx") && !baseline_forced() {
            // SAFETY: the processor has AVX, checked just above.
            return unsafe { avx(f) };
        }
    }
    f()
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
unsafe fn avx<R>(f: impl FnOnce() -> R) -> R {
    f()
}

#[cfg(test)]
thread_local! {
    static BASELINE: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Tests run the baseline code on this thread while this is set.
#[cfg(test)]
pub(crate) fn force_baseline(on: bool) {
    BASELINE.with(|b| b.set(on));
}

#[cfg(test)]
fn baseline_forced() -> bool {
    BASELINE.with(|b| b.get())
}

#[cfg(not(test))]
#[inline(always)]
fn baseline_forced() -> bool {
    false
}

//! The compensation inner loop (nominal forward kinematics + damped least-squares IK on the
//! calibrated model) does not allocate: counted with a global allocator wrapper, per thread (the
//! test harness's own thread may allocate meanwhile).

use robocal_core::{preset, Compensator, DampedLeastSquares};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

struct Counting;

thread_local! {
    /// Allocations made by the current thread.
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

fn count() {
    let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
}

fn allocations() -> usize {
    ALLOCATIONS.with(|c| c.get())
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn compensate_does_not_allocate() {
    let nom = preset("kuka-kr480-r3330").unwrap();
    let cal = preset("kuka-kr480-r3330-table3").unwrap();
    let comp = Compensator::new(&nom, &cal, DampedLeastSquares::default()).unwrap();
    // Deterministic poses spread over the joint ranges (no RNG: nothing else runs in between).
    let poses: Vec<[f64; 6]> = (0..500)
        .map(|k| {
            let f = |a: f64, lo: f64, hi: f64| {
                let u = (k as f64 * a).fract();
                (lo + u * (hi - lo)).to_radians()
            };
            [
                f(0.618, -185.0, 185.0),
                f(0.414, -130.0, 20.0),
                f(0.732, -100.0, 144.0),
                f(0.236, -350.0, 350.0),
                f(0.32, -120.0, 120.0),
                f(0.577, -350.0, 350.0),
            ]
        })
        .collect();
    let mut q = [0.0; 6];
    let mut converged = 0;
    let before = allocations();
    for d in &poses {
        let (_, rep) = comp.compensate(d, &mut q);
        converged += rep.status.is_converged() as usize;
    }
    let after = allocations();
    assert_eq!(after - before, 0, "allocations in the compensation loop");
    assert!(converged >= 495, "{converged}");
    // Cartesian targets from the default seeds: no allocation either.
    let targets: Vec<_> = poses.iter().map(|d| cal.tool_position(d)).collect();
    let before = allocations();
    let mut reached = 0;
    for t in &targets {
        reached += comp.reach(t, None, &mut q).status.is_converged() as usize;
    }
    let after = allocations();
    assert_eq!(after - before, 0, "allocations in reach");
    assert_eq!(reached, targets.len());
}

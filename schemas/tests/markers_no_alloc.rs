//! `/contact_markers` costs no allocation per sample: after the first update, updating the
//! message (every mode, forces of both signs, zero force, huge forces whose labels are longest,
//! moving points and hands, the labels rewritten, contacts separating and touching again)
//! allocates nothing (a counting global allocator, per thread).

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use schemas::markers::{ContactMarkers, ContactSample, ForceScale, MarkerContact, MarkerMode};

struct Counting;

thread_local! {
    static ALLOCS: Cell<u64> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ = ALLOCS.try_with(|c| c.set(c.get() + 1));
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let _ = ALLOCS.try_with(|c| c.set(c.get() + 1));
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocs() -> u64 {
    ALLOCS.with(|c| c.get())
}

#[test]
fn updating_the_contact_markers_does_not_allocate() {
    let contacts: Vec<MarkerContact> =
        ["elbow4", "elbow7", "hand"].iter().map(|s| MarkerContact { name: s.to_string(), normal: [0.0, 0.6, 0.8], offset: 0.05 }).collect();
    let mut m = ContactMarkers::new("world", &contacts, ForceScale::for_arm(1.0, 3.0, 10));
    let modes = [MarkerMode::Separated, MarkerMode::Sticking, MarkerMode::Sliding, MarkerMode::Pushing, MarkerMode::Pulling];
    let sample = |k: usize, i: usize| ContactSample {
        point: [0.1 * k as f64, 0.01 * i as f64, 0.0],
        force: if i.is_multiple_of(7) { [0.0; 3] } else if i.is_multiple_of(11) { [1e300, 0.0, 0.0] } else { [0.5 * i as f64, -1.0, 30.0 - i as f64] },
        mode: modes[(i + k) % modes.len()],
    };
    m.update(0, (0..3).map(|k| sample(k, 0)), [0.0; 3], [0.0; 3]);
    let before = allocs();
    let (mut entities, mut deletions) = (0, 0);
    for i in 1..200 {
        let msg = m.update(i as u64 * 1_000_000, (0..3).map(|k| sample(k, i)), [0.01 * i as f64, 0.0, 0.4], [0.0, 0.01 * i as f64, 0.4]);
        entities += msg.entities.len();
        deletions += msg.deletions.len();
    }
    assert_eq!(allocs() - before, 0, "allocations in 199 updates");
    // a contact touching is drawn (two entities), a separated one is not, and is deleted (two
    // deletions) at the sample it separates: one of the three contacts is separated at each
    // sample, a different one each time
    let separated = |k: usize, i: usize| sample(k, i).mode == MarkerMode::Separated;
    let drawn: usize = (1..200).map(|i| (0..3).filter(|&k| !separated(k, i)).count()).sum();
    let separations: usize = (1..200).map(|i| (0..3).filter(|&k| separated(k, i) && !separated(k, i - 1)).count()).sum();
    assert_eq!(entities, 199 * 2 + 2 * drawn);
    assert_eq!(deletions, 2 * separations);
    assert!(separations > 100, "{separations}");
}

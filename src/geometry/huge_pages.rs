//! Large read-mostly arrays (BVH nodes, triangle packs) in 2 MiB pages where the system allows.
//!
//! Rays visit the hierarchy of a large scene in no order that memory pages follow, so with
//! 4 KiB pages nearly every node fetched also misses the TLB; a 2 MiB page covers 512 times as
//! much. On Linux with transparent huge pages in `madvise` mode (the common default), memory is
//! given huge pages when asked with `madvise(MADV_HUGEPAGE)` before it is first written, as
//! Embree does for its BVH (`os_malloc`). Elsewhere, or where the kernel declines, the arrays
//! are ordinary allocations: the hint changes speed, never results.

/// Arrays smaller than this gain nothing from huge pages.
const HUGE_PAGE: usize = 2 << 20;

/// A copy of `items` in memory asked to be backed by huge pages, with no spare capacity.
pub fn copy<T: Copy>(items: &[T]) -> Vec<T> {
    let mut copy = Vec::with_capacity(items.len());
    let bytes = std::mem::size_of_val(items);
    if bytes >= 2 * HUGE_PAGE {
        advise(copy.as_mut_ptr() as *mut u8, bytes);
    }
    copy.extend_from_slice(items);
    copy
}

#[cfg(target_os = "linux")]
fn advise(start: *mut u8, bytes: usize) {
    // The whole huge pages inside the allocation.
    let first = (start as usize).next_multiple_of(HUGE_PAGE);
    let end = (start as usize + bytes) / HUGE_PAGE * HUGE_PAGE;
    if end > first {
        // SAFETY: the range lies inside an allocation this function's caller owns; the advice
        // only changes how the kernel backs it, never its contents. A failure is harmless.
        unsafe {
            libc::madvise(first as *mut libc::c_void, end - first, libc::MADV_HUGEPAGE);
        }
    }
}

#[cfg(not(target_os = "linux"))]
fn advise(_start: *mut u8, _bytes: usize) {}

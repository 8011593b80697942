//! Limits and hostile inputs, in a binary of their own: its allocator
//! (`peak`) measures the whole process's heap, so no other test may run
//! beside them.

#[global_allocator]
static ALLOC: peak::Counting = peak::Counting;

#[path = "../peak/mod.rs"]
mod peak;

mod fuzz_levels;
mod ldtk;
mod limits;

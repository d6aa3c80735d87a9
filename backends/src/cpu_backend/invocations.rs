//! A batch's invocations and memory ([`super::batch`]): where each invocation is and who it
//! is, and the register files, private and workgroup memory they run on. Shared by the
//! dispatch that makes them ([`super::dispatch`]), the group loop that runs them
//! ([`super::interp`]) and the completion of barriers and subgroup operations
//! ([`super::sync_point`]).

use super::memory::Frame;

/// One invocation: where it is (its running frame, its callers' frames) and who it is.
/// Its registers are its column of each code's file, its private memory its slice of
/// [`Batch::private`].
pub(super) struct Invocation {
    /// The running frame (`None` once the entry point returned).
    pub frame: Option<Frame>,
    /// Callers of the running frame, outermost first.
    pub callers: Vec<Frame>,
    /// Subgroup lane, subgroup index and size, local index (for gathers).
    pub lane: u32,
    /// Index of the invocation's subgroup.
    pub subgroup_id: u32,
    /// Invocations per subgroup.
    pub subgroup_size: u32,
    /// `local_invocation_index`.
    pub local_index: u32,
    /// Its index in the SIMT count ([`super::counts::DispatchCounts`]): its local index,
    /// after a warp boundary per earlier workgroup of its batch ([`super::batch`]).
    pub simt_index: u32,
}

/// The memory of a batch's invocations ([`super::batch`]), kept by a worker thread from
/// one batch to the next (register files of tens of kilobytes per invocation cost more in
/// page faults than the kernels' work when allocated anew).
pub(super) struct Batch {
    /// Per code, its lane-minor register file (empty until the code first runs).
    pub files: Vec<Vec<u32>>,
    /// Every invocation's private memory, `private_words` each, in the batch's order
    /// (workgroup after workgroup, each in local-index order).
    pub private: Vec<u32>,
    /// Words of private memory per invocation.
    pub private_words: usize,
    /// The workgroup memory of the batch's workgroups, the program's `workgroup_words`
    /// each, in order.
    pub shared: Vec<u32>,
    /// Fuel left before the time limit is looked at ([`super::limit`]).
    pub fuel: u32,
    /// The worker's sanitizer state, when the dispatch sanitizes.
    pub sanitizing: Option<super::sanitize::Local>,
}

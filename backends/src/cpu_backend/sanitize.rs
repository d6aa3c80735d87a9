//! The interpreter as a sanitizer ([`super::CpuOptions::sanitize`]): while it runs a
//! kernel it reports what WGSL leaves undefined or what only zero-initialisation makes
//! defined, each finding with its kind, WGSL file, line and function and a short detail,
//! deduplicated per WGSL line and counted (at most [`MAX_FINDINGS`] sites).
//!
//! What it detects:
//! - **out-of-range indices**: an index at or past the length of an array (fixed or
//!   runtime-sized), vector or matrix, through a pointer or into a value, and fused
//!   element loads; loads and stores of buffer words past the binding's end. The
//!   interpreter clamps the index (naga's `Restrict` policy), GPU paths read 0 and drop
//!   the write (robust buffer access); WGSL allows either, so the result is undefined.
//! - **reads of workgroup memory no invocation wrote** in this dispatch (its own
//!   workgroup's copy), atomics included: WGSL zero-initialises workgroup memory, so
//!   the result is defined, but it relies on that zeroing, which a path that skips it
//!   gets wrong (a note, not undefined behaviour).
//! - **data races**: two different invocations accessing the same word, at least one of
//!   them a non-atomic write, unordered: in workgroup memory with no
//!   `workgroupBarrier` (or `workgroupUniformLoad`) between them; in storage buffers
//!   from different workgroups (nothing orders them within a dispatch) or from one
//!   workgroup with no `storageBarrier` between. Atomics never race with atomics.
//! - **barriers and subgroup operations in non-uniform control flow** (an error of the
//!   dispatch as always, and a finding).
//!
//! How: the sanitizing program is compiled apart (its own cache entry), without
//! if-conversion (which evaluates both branches' loads and indices: their accesses would
//! be reported although WGSL never makes them), and every instruction that indexes or
//! touches workgroup or buffer memory is wrapped in [`Insn::Checked`](super::insn::Insn::Checked)
//! ([`super::decode`]): the group loop calls [`super::checked::execute`], which checks
//! each member's access ([`check_access`]), records it in a shadow word
//! (the last write, the last two different readers, with the invocation, the barrier
//! epoch and the instruction), then runs the instruction as usual. The normal program
//! holds no checked instruction, so the normal mode pays nothing.
//!
//! Where: this file holds what the sanitizer knows (findings, shadows, the check of one
//! access) and reads only the compiled [`Program`]; it sits below the executor, whose
//! group memory carries a [`Sanitizing`]. The instructions are wrapped by the compiler
//! ([`super::decode`]) and checked at run time in [`super::checked`].
//!
//! What it does not detect, and why:
//! - function-space (`var` in a function) and private variables read before written:
//!   WGSL and every naga backend zero-initialise them, so no path differs; and the
//!   compiler's register passes (a load reading its variable's registers in place,
//!   values computed straight into variables, registers reused once a value is dead) make
//!   per-register tracking unreliable.
//! - races through half-words (`f16` in buffers: two invocations writing the two halves
//!   of one word touch different WGSL memory locations, which a shadow per word cannot
//!   tell apart), textures (loads and stores out of range are the texture corpus's
//!   rule: out-of-range stores are dropped everywhere, loads judged against the texels
//!   WGSL allows), and private memory (per invocation: it cannot race).
//! - races between accesses more than the last write and two readers apart, or
//!   separated by a multiple of 16 384 barriers (epochs are kept in 14 bits), and
//!   storage words past the shadow's cap ([`SHADOW_CAP_WORDS`] words per dispatch): a
//!   finding is always real, an absent one is not a proof.

use super::memory::{BUFFER, TAG_MASK, WORKGROUP};
use super::program::Program;
use std::collections::HashMap;
use std::fmt;
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};

/// At most this many findings (distinct instructions and kinds) per dispatch; further
/// ones are counted only.
pub const MAX_FINDINGS: usize = 64;

/// Storage words a dispatch's shadow covers at most (32 bytes each: 1 GiB); accesses to
/// words past it are not checked for races.
pub(super) const SHADOW_CAP_WORDS: u64 = 1 << 25;

/// Storage shadow words per lock.
const CHUNK: usize = 1024;

/// What a finding is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum FindingKind {
    /// An index at or past the length of an array, vector or matrix.
    OutOfRangeIndex,
    /// A load or store of buffer words past the binding's end.
    PastBindingEnd,
    /// A read of workgroup memory that no invocation of the workgroup wrote in the
    /// dispatch: defined (zero) by WGSL, but only through zero-initialisation.
    UnwrittenWorkgroupRead,
    /// Two invocations of a workgroup access a word of workgroup memory, one a
    /// non-atomic write, with no `workgroupBarrier` between.
    WorkgroupRace,
    /// Two invocations access a storage buffer word, one a non-atomic write, from
    /// different workgroups or with no `storageBarrier` between.
    StorageRace,
    /// A barrier or subgroup operation reached in non-uniform control flow.
    NonUniformBarrier,
}

impl FindingKind {
    /// Whether WGSL leaves the kernel's results undefined where this happens (out of
    /// range, races, non-uniform barriers), rather than defined through
    /// zero-initialisation.
    pub fn undefined(self) -> bool {
        self != FindingKind::UnwrittenWorkgroupRead
    }

    /// The kind in a few words.
    pub fn name(self) -> &'static str {
        match self {
            FindingKind::OutOfRangeIndex => "out-of-range index",
            FindingKind::PastBindingEnd => "access past a binding's end",
            FindingKind::UnwrittenWorkgroupRead => "read of workgroup memory no invocation wrote",
            FindingKind::WorkgroupRace => "data race on workgroup memory",
            FindingKind::StorageRace => "data race on storage memory",
            FindingKind::NonUniformBarrier => "barrier in non-uniform control flow",
        }
    }
}

/// One thing the sanitizer found, at one instruction.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Finding {
    /// What it is.
    pub kind: FindingKind,
    /// The kernel's name (an outside kernel's: its entry point).
    pub kernel: String,
    /// The WGSL file (of a registry kernel composed of several, the one holding the
    /// line; empty where the IR has no span).
    pub file: String,
    /// The line in that file (0 where the IR has no span).
    pub line: u32,
    /// The WGSL function.
    pub function: String,
    /// The first occurrence: the index and length, the two invocations, the word.
    pub detail: String,
    /// How many times it happened (every invocation and word).
    pub count: u64,
}

impl fmt::Display for Finding {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} at {}:{} in `{}` ({}", self.kind.name(), self.file, self.line, self.function, self.detail)?;
        if self.count > 1 {
            write!(f, "; {} times", self.count)?;
        }
        write!(f, ")")
    }
}

/// A finding's place: (kind, code, instruction).
type Site = (FindingKind, u32, u32);

/// The findings of a dispatch, shared by its worker threads.
#[derive(Default)]
struct Found {
    findings: Vec<Finding>,
    sites: HashMap<Site, usize>,
    /// Occurrences past [`MAX_FINDINGS`] sites.
    dropped: u64,
}

/// An access in a shadow word: [`VALID`], [`ATOMIC`], the barrier epoch and the
/// invocation (workgroup × invocations per workgroup + local index).
type Access = u64;
const VALID: u64 = 1 << 63;
const ATOMIC: u64 = 1 << 62;
const EPOCH_SHIFT: u32 = 48;
const EPOCH_MASK: u64 = (1 << 14) - 1;
const ID_MASK: u64 = (1 << EPOCH_SHIFT) - 1;

/// The last accesses to one word.
#[derive(Clone, Copy, Default)]
pub(super) struct Shadow {
    /// The last write (0: none in this dispatch).
    write: Access,
    /// The last two different readers since that write.
    reads: [Access; 2],
    /// Where the write and the readers were ([`site_of`]).
    write_site: u32,
    read_sites: [u32; 2],
}

/// How an instruction touches a word.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Op {
    Read,
    Write,
    Atomic,
}

/// The instruction `pc` of code `code` in a shadow word (`u32::MAX` past its range).
pub(super) fn site_of(code: u32, pc: u32) -> u32 {
    if code < 1 << 12 && pc < 1 << 20 { code << 20 | pc } else { u32::MAX }
}

/// One dispatch's sanitizer state shared by its worker threads: the storage buffers'
/// shadow words and the findings.
pub(super) struct Sanitizer {
    /// Invocations per workgroup.
    per_workgroup: u64,
    /// The dispatch's workgroups.
    workgroups: [u32; 3],
    /// Per binding, its words' shadows in locked chunks (allocated when first touched).
    storage: Vec<Box<[Mutex<Vec<Shadow>>]>>,
    /// Storage shadow words allocated so far (capped at [`SHADOW_CAP_WORDS`]).
    shadow_words: AtomicU64,
    found: Mutex<Found>,
}

/// A worker thread's sanitizer state: its batch's workgroup shadows, epochs and the
/// sites it already reported.
#[derive(Default)]
pub(super) struct Local {
    /// One shadow per word of the batch's workgroup memory.
    pub workgroup: Vec<Shadow>,
    /// The invocation of the batch's first lane.
    pub first_id: u64,
    /// Workgroup barriers passed in this batch.
    workgroup_epoch: u64,
    /// Storage barriers passed in this batch.
    storage_epoch: u64,
    /// Sites this thread reported, with occurrences not yet counted in the shared list.
    seen: HashMap<Site, u64>,
}

impl Local {
    /// Starts a batch whose first lane is invocation `first_id`.
    pub(super) fn start_batch(&mut self, first_id: u64) {
        self.first_id = first_id;
        self.workgroup_epoch = 0;
        self.storage_epoch = 0;
    }

    /// Passes a barrier of the whole batch: `workgroup` orders workgroup memory,
    /// `storage` storage buffers.
    pub(super) fn barrier(&mut self, workgroup: bool, storage: bool) {
        self.workgroup_epoch += u64::from(workgroup);
        self.storage_epoch += u64::from(storage);
    }

    /// Records an occurrence of `kind` at instruction `pc` of code `code`; `detail` is
    /// asked for only the first time this thread sees the site.
    pub(super) fn found(
        &mut self,
        shared: &Sanitizer,
        program: &Program,
        (kind, code, pc): Site,
        detail: impl FnOnce() -> String,
    ) {
        match self.seen.get_mut(&(kind, code, pc)) {
            Some(count) => *count += 1,
            None => {
                self.seen.insert((kind, code, pc), 0);
                shared.add(program, (kind, code, pc), detail(), 1);
            }
        }
    }

    /// Adds the occurrences counted here to the shared findings.
    pub(super) fn flush(&mut self, shared: &Sanitizer, program: &Program) {
        for (site, count) in self.seen.iter_mut() {
            if *count > 0 {
                shared.add(program, *site, String::new(), *count);
                *count = 0;
            }
        }
    }
}

impl Sanitizer {
    /// The state of a dispatch of `workgroups` of `per_workgroup` invocations over
    /// buffers of `words` words each.
    pub(super) fn new(per_workgroup: u32, workgroups: [u32; 3], words: impl Iterator<Item = usize>) -> Self {
        let storage = words
            .map(|words| (0..words.div_ceil(CHUNK)).map(|_| Mutex::new(Vec::new())).collect::<Box<[_]>>())
            .collect();
        Self {
            per_workgroup: u64::from(per_workgroup.max(1)),
            workgroups,
            storage,
            shadow_words: AtomicU64::new(0),
            found: Mutex::new(Found::default()),
        }
    }

    /// Adds `count` occurrences at `site` (with `detail` if the site is new).
    fn add(&self, program: &Program, site: Site, detail: String, count: u64) {
        let mut found = self.found.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        if let Some(&at) = found.sites.get(&site) {
            found.findings[at].count += count;
        } else if found.findings.len() < MAX_FINDINGS && !detail.is_empty() {
            let (kind, code, pc) = site;
            let (file, line, function) = program.place(code, pc);
            let finding = Finding { kind, kernel: program.kernel.clone(), file, line, function, detail, count };
            let at = found.findings.len();
            found.findings.push(finding);
            found.sites.insert(site, at);
        } else {
            found.dropped += count;
        }
    }

    /// The dispatch's findings, in order of WGSL line, and the occurrences past
    /// [`MAX_FINDINGS`] sites.
    pub(super) fn into_findings(self) -> (Vec<Finding>, u64) {
        let found = self.found.into_inner().unwrap_or_else(std::sync::PoisonError::into_inner);
        // One per WGSL place and kind: the instructions of one line (an unrolled loop,
        // a function inlined twice) count together, the first one's detail kept.
        let mut findings: Vec<Finding> = Vec::with_capacity(found.findings.len());
        for finding in found.findings {
            let same = |f: &&mut Finding| {
                (f.kind, &f.file, f.line, &f.function) == (finding.kind, &finding.file, finding.line, &finding.function)
            };
            match findings.iter_mut().find(same) {
                Some(first) => first.count += finding.count,
                None => findings.push(finding),
            }
        }
        findings.sort_by(|a, b| (&a.file, a.line, a.kind).cmp(&(&b.file, b.line, b.kind)));
        (findings, found.dropped)
    }

    /// Invocation `id` as people read it.
    fn invocation(&self, id: u64) -> String {
        let (flat, local) = (id / self.per_workgroup, id % self.per_workgroup);
        let [wx, wy, _] = self.workgroups.map(|n| u64::from(n.max(1)));
        format!("invocation {local} of workgroup ({}, {}, {})", flat % wx, flat / wx % wy, flat / (wx * wy))
    }

    /// Whether accesses `a` and `b` (to the same word) are unordered: different
    /// invocations of different workgroups, or of one workgroup in the same epoch.
    fn unordered(&self, a: Access, b: Access) -> bool {
        let (ia, ib) = (a & ID_MASK, b & ID_MASK);
        a & VALID != 0
            && ia != ib
            && (ia / self.per_workgroup != ib / self.per_workgroup
                || (a >> EPOCH_SHIFT) & EPOCH_MASK == (b >> EPOCH_SHIFT) & EPOCH_MASK)
    }

    /// Records access `me` (at `site`) to `shadow`; returns the earlier access it races
    /// with (the access, its site, whether it was a write).
    fn touch(&self, shadow: &mut Shadow, op: Op, me: Access, site: u32) -> Option<(Access, u32, bool)> {
        let write_races = self.unordered(shadow.write, me) && (op == Op::Write || shadow.write & ATOMIC == 0);
        let mut race = write_races.then_some((shadow.write, shadow.write_site, true));
        match op {
            Op::Read => {
                if shadow.reads[0] & ID_MASK != me & ID_MASK {
                    shadow.reads[1] = shadow.reads[0];
                    shadow.read_sites[1] = shadow.read_sites[0];
                }
                shadow.reads[0] = me;
                shadow.read_sites[0] = site;
            }
            Op::Write | Op::Atomic => {
                if race.is_none() && op == Op::Write {
                    race = (0..2)
                        .find(|&r| self.unordered(shadow.reads[r], me))
                        .map(|r| (shadow.reads[r], shadow.read_sites[r], false));
                }
                shadow.write = me | if op == Op::Atomic { ATOMIC } else { 0 };
                shadow.write_site = site;
                shadow.reads = [0; 2];
            }
        }
        race
    }
}

/// The sanitizer as a running group sees it.
pub(super) struct Sanitizing<'a> {
    /// The dispatch's state.
    pub shared: &'a Sanitizer,
    /// The worker thread's.
    pub local: &'a mut Local,
}

/// What one member's access touches, for [`check_access`].
pub(super) struct Touch {
    pub op: Op,
    /// A pointer tag's region ([`BUFFER`] with its binding, [`WORKGROUP`]), or another
    /// region (not checked).
    pub tag: u32,
    /// First word (in the region: a buffer's words, the workgroup's words).
    pub word: usize,
    /// Words.
    pub len: usize,
}

/// Checks one member's touch: past a binding's end, unwritten workgroup words, races.
#[allow(clippy::too_many_arguments)]
pub(super) fn check_access(
    shared: &Sanitizer,
    local: &mut Local,
    program: &Program,
    (code, pc, site): (u32, u32, u32),
    me: u64,
    touch: &Touch,
    buffer_words: &dyn Fn(u32) -> usize,
    binding: &dyn Fn(u32) -> String,
    region: usize,
) {
    let kind_of = |op: Op| match op {
        Op::Read => "reads",
        Op::Write => "writes",
        Op::Atomic => "atomically updates",
    };
    match touch.tag & TAG_MASK {
        BUFFER => {
            let slot = touch.tag & !TAG_MASK;
            let words = buffer_words(touch.tag);
            if touch.word + touch.len > words {
                local.found(shared, program, (FindingKind::PastBindingEnd, code, pc), || {
                    format!(
                        "{} words {}..{} of {}, which has {words}",
                        kind_of(touch.op),
                        touch.word,
                        touch.word + touch.len,
                        binding(slot)
                    )
                });
            }
            let me = me.min(ID_MASK) | VALID | (local.storage_epoch & EPOCH_MASK) << EPOCH_SHIFT;
            let Some(chunks) = shared.storage.get(slot as usize) else { return };
            for word in touch.word..(touch.word + touch.len).min(words) {
                let Some(chunk) = chunks.get(word / CHUNK) else { continue };
                let mut chunk = chunk.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
                if chunk.is_empty() {
                    let total = shared.shadow_words.fetch_add(CHUNK as u64, Ordering::Relaxed);
                    if total + CHUNK as u64 > SHADOW_CAP_WORDS || chunk.try_reserve_exact(CHUNK).is_err() {
                        continue;
                    }
                    chunk.resize(CHUNK, Shadow::default());
                }
                if let Some((other, other_site, wrote)) = shared.touch(&mut chunk[word % CHUNK], touch.op, me, site) {
                    drop(chunk);
                    local.found(shared, program, (FindingKind::StorageRace, code, pc), || {
                        let order = if (other & ID_MASK) / shared.per_workgroup == (me & ID_MASK) / shared.per_workgroup
                        {
                            "with no storageBarrier between"
                        } else {
                            "from another workgroup: never ordered in a dispatch"
                        };
                        format!(
                            "{} {} word {word} of {} that {} {} at {}, {order}",
                            shared.invocation(me & ID_MASK),
                            kind_of(touch.op),
                            binding(slot),
                            shared.invocation(other & ID_MASK),
                            if wrote { "wrote" } else { "read" },
                            line_of(program, other_site),
                        )
                    });
                }
            }
        }
        WORKGROUP => {
            let me = me.min(ID_MASK) | VALID | (local.workgroup_epoch & EPOCH_MASK) << EPOCH_SHIFT;
            let words = program.workgroup_words as usize;
            for word in touch.word..(touch.word + touch.len).min(words) {
                let Some(shadow) = local.workgroup.get_mut(region + word) else { continue };
                let unwritten = shadow.write == 0 && touch.op != Op::Write;
                let race = shared.touch(shadow, touch.op, me, site);
                let name = || workgroup_word(program, word);
                if unwritten {
                    local.found(shared, program, (FindingKind::UnwrittenWorkgroupRead, code, pc), || {
                        format!(
                            "{} reads {} before any invocation of its workgroup wrote it: the zero WGSL \
                             initialises workgroup memory with",
                            shared.invocation(me & ID_MASK),
                            name()
                        )
                    });
                }
                if let Some((other, other_site, wrote)) = race {
                    local.found(shared, program, (FindingKind::WorkgroupRace, code, pc), || {
                        format!(
                            "{} {} {} that {} {} at {}, with no workgroupBarrier between",
                            shared.invocation(me & ID_MASK),
                            kind_of(touch.op),
                            name(),
                            shared.invocation(other & ID_MASK),
                            if wrote { "wrote" } else { "read" },
                            line_of(program, other_site),
                        )
                    });
                }
            }
        }
        _ => {}
    }
}

/// The WGSL place (`file:line`) of a shadow's site.
fn line_of(program: &Program, site: u32) -> String {
    let (code, pc) = (site >> 20, site & ((1 << 20) - 1));
    if program.codes.get(code as usize).is_none_or(|c| c.lines.len() <= pc as usize) {
        return "an unknown line".into();
    }
    let (file, line, _) = program.place(code, pc);
    format!("{file}:{line}")
}

/// Word `word` of workgroup memory as its variable and word: "word 3 of `tile`".
fn workgroup_word(program: &Program, word: usize) -> String {
    match program.workgroup_variables.iter().find(|(start, words, _)| (*start..start + words).contains(&(word as u32)))
    {
        Some((start, _, name)) => format!("word {} of `{name}`", word as u32 - start),
        None => format!("workgroup word {word}"),
    }
}

//! Where the invocations of a batch stand while they all run one code under the same
//! callers: per instruction of that code, the set of invocations whose next instruction
//! it is, and which instructions have any. The scheduler of [`super::interp`] runs the set of the
//! smallest such instruction next and stops it at the next one.
//!
//! Why: found by scanning every invocation's next instruction, each group cost the
//! scheduler three passes over the batch; a divergent kernel's groups had a tenth of a
//! 512-wide batch or fewer, so those passes were a seventh of the path tracer's time.
//! Here a group costs its members and a few words.

/// Bits per word of a set.
const BITS: usize = 64;

/// The invocations at each instruction, as bit sets (`words` words per instruction).
#[derive(Default)]
pub(super) struct Places {
    /// Words per set: invocations / 64, rounded up.
    words: usize,
    /// Per instruction index, its set of invocations.
    sets: Vec<u64>,
    /// Bit per instruction index: whether its set has a member.
    occupied: Vec<u64>,
}

impl Places {
    /// Starts over for a code of `instructions` instructions, `lanes` invocations, of
    /// which those of `running` (lane, instruction) are at those instructions.
    pub(super) fn rebuild(
        &mut self,
        instructions: usize,
        lanes: usize,
        running: impl IntoIterator<Item = (usize, u32)>,
    ) {
        let words = lanes.div_ceil(BITS);
        let slots = instructions + 1;
        if self.words != words || self.sets.len() != slots * words {
            self.words = words;
            self.sets = vec![0; slots * words];
            self.occupied = vec![0; slots.div_ceil(BITS)];
        } else {
            // Only sets left behind by an earlier use (a dispatch that failed) are not
            // empty.
            while let Some(pc) = self.next_occupied(0) {
                self.sets[pc * words..][..words].fill(0);
                self.occupied[pc / BITS] &= !(1 << (pc % BITS));
            }
        }
        for (lane, pc) in running {
            self.add(pc, lane);
        }
    }

    /// Puts invocation `lane` at instruction `pc`.
    #[inline(always)]
    pub(super) fn add(&mut self, pc: u32, lane: usize) {
        let pc = pc as usize;
        self.sets[pc * self.words + lane / BITS] |= 1 << (lane % BITS);
        self.occupied[pc / BITS] |= 1 << (pc % BITS);
    }

    /// Puts the invocations of the set `lanes` (a bit per invocation, as the sets here)
    /// at instruction `pc`, except those of `except` where given: a group's members
    /// moved on together, a word at a time rather than a member at a time.
    pub(super) fn add_set(&mut self, pc: u32, lanes: &[u64], except: Option<&[u64]>) {
        let pc = pc as usize;
        let set = &mut self.sets[pc * self.words..][..self.words];
        let mut any = 0;
        for (w, (slot, &bits)) in set.iter_mut().zip(lanes).enumerate() {
            let bits = bits & !except.map_or(0, |except| except[w]);
            *slot |= bits;
            any |= bits;
        }
        if any != 0 {
            self.occupied[pc / BITS] |= 1 << (pc % BITS);
        }
    }

    /// Takes the invocations at the smallest instruction with any: puts their set in
    /// `lanes` (a bit per invocation, [`members_of`] lists them) and returns that
    /// instruction and the next one with invocations (`u32::MAX` if none); `None` when no
    /// invocation is left.
    pub(super) fn take_first(&mut self, lanes: &mut Vec<u64>) -> Option<(u32, u32)> {
        let pc = self.next_occupied(0)?;
        self.occupied[pc / BITS] &= !(1 << (pc % BITS));
        lanes.clear();
        lanes.extend(self.sets[pc * self.words..][..self.words].iter_mut().map(std::mem::take));
        let next = self.next_occupied(pc + 1).map_or(u32::MAX, |next| next as u32);
        Some((pc as u32, next))
    }

    /// Empties every set, calling `f(lane, instruction)` for each invocation in one: where
    /// the scheduler writes the invocations' places back into their frames before it
    /// leaves them to the frames (a call by some of them, a return from a call).
    pub(super) fn drain(&mut self, mut f: impl FnMut(usize, u32)) {
        while let Some(pc) = self.next_occupied(0) {
            self.occupied[pc / BITS] &= !(1 << (pc % BITS));
            let set = &mut self.sets[pc * self.words..][..self.words];
            lanes_in(set).for_each(|lane| f(lane, pc as u32));
            set.fill(0);
        }
    }

    /// Whether no instruction has an invocation.
    pub(super) fn is_empty(&self) -> bool {
        self.next_occupied(0).is_none()
    }

    /// The smallest instruction from `from` on with invocations.
    fn next_occupied(&self, from: usize) -> Option<usize> {
        let mut w = from / BITS;
        let mut bits = self.occupied.get(w)? & (u64::MAX << (from % BITS));
        loop {
            if bits != 0 {
                return Some(w * BITS + bits.trailing_zeros() as usize);
            }
            w += 1;
            bits = *self.occupied.get(w)?;
        }
    }
}

/// The invocations of the set `lanes` (a bit per invocation), in increasing order.
pub(super) fn lanes_in(lanes: &[u64]) -> impl Iterator<Item = usize> + '_ {
    lanes.iter().enumerate().flat_map(|(w, &word)| {
        std::iter::successors((word != 0).then_some(word), |&bits| Some(bits & (bits - 1)).filter(|&b| b != 0))
            .map(move |bits| w * BITS + bits.trailing_zeros() as usize)
    })
}

/// Appends the invocations of the set `lanes` (a bit per invocation) to `members`, in
/// increasing order.
pub(super) fn members_of(lanes: &[u64], members: &mut Vec<usize>) {
    let start = members.len();
    members.resize(start + lanes.iter().map(|bits| bits.count_ones() as usize).sum::<usize>(), 0);
    // Written through a slice, not pushed: a push stores the list's length every time.
    let mut slots = members[start..].iter_mut();
    for (w, &word) in lanes.iter().enumerate() {
        let mut bits = word;
        while bits != 0 {
            *slots.next().expect("a slot per bit") = w * BITS + bits.trailing_zeros() as usize;
            bits &= bits - 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{Places, lanes_in, members_of};

    #[test]
    fn groups_come_out_furthest_behind_first_with_their_meeting_point() {
        let mut places = Places::default();
        // 130 lanes (three words per set): lanes 1, 64 and 129 at 7, lane 3 at 2, the
        // rest stopped.
        places.rebuild(100, 130, [(1, 7), (64, 7), (129, 7), (3, 2)]);
        let (mut members, mut lanes) = (Vec::new(), Vec::new());
        // What the scheduler takes: the set, listed.
        let mut take = |places: &mut Places, members: &mut Vec<usize>| {
            let first = places.take_first(&mut lanes);
            members_of(&lanes, members);
            first
        };
        assert_eq!(take(&mut places, &mut members), Some((2, 7)));
        assert_eq!(members, [3]);
        // Lane 3 runs on to 99, the last instruction index + 0 (a code's end).
        places.add(99, 3);
        members.clear();
        assert_eq!(take(&mut places, &mut members), Some((7, 99)));
        assert_eq!(members, [1, 64, 129]);
        members.clear();
        assert_eq!(take(&mut places, &mut members), Some((99, u32::MAX)));
        assert_eq!(members, [3]);
        // Lane 4 comes back to 2 (a loop): alone there (the set was emptied).
        places.add(2, 4);
        members.clear();
        assert_eq!(take(&mut places, &mut members), Some((2, u32::MAX)));
        assert_eq!(members, [4]);
        members.clear();
        assert_eq!(take(&mut places, &mut members), None);
        // Sets left behind are emptied by the next rebuild.
        places.add(5, 0);
        places.rebuild(100, 130, []);
        assert_eq!(take(&mut places, &mut members), None);
    }

    #[test]
    fn sets_move_a_word_at_a_time_and_drain_back_to_lanes() {
        let mut places = Places::default();
        places.rebuild(10, 130, [(0, 4), (65, 4), (129, 4), (2, 6)]);
        let (mut members, mut lanes) = (Vec::new(), Vec::new());
        assert_eq!(places.take_first(&mut lanes), Some((4, 6)));
        members_of(&lanes, &mut members);
        assert_eq!(members, [0, 65, 129]);
        assert_eq!(lanes_in(&lanes).collect::<Vec<_>>(), members);
        assert_eq!(lanes, [1, 1 << 1, 1 << 1]);
        // A branch: lane 65 jumps to 9, the others fall through to 5; an empty set
        // leaves its instruction unoccupied.
        let taken = [0, 1 << 1, 0];
        places.add_set(9, &taken, None);
        places.add_set(5, &lanes, Some(&taken));
        places.add_set(7, &[0, 0, 0], None);
        let mut drained = Vec::new();
        places.drain(|lane, pc| drained.push((lane, pc)));
        assert_eq!(drained, [(0, 5), (129, 5), (2, 6), (65, 9)]);
        assert_eq!(places.take_first(&mut lanes), None);
    }
}

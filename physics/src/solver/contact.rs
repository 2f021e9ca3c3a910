//! Contact points as the solvers see them, and the simplest solver: one contact at a time.

use super::SolverBody;
use crate::body::BodyHandle;
use crate::collide::FeatureId;
use crate::math::{Vec2, clamp, cross, perp};

/// The last solve's contact impulses by (body A, body B, feature), for warm starting the
/// next: kept in contact order, which is by body pair as the broad phase lists pairs.
#[derive(Debug, Clone, Default)]
pub(crate) struct ContactMemory {
    entries: Vec<Entry>,
}

impl ContactMemory {
    /// Writes each contact's impulses from `impulses` (by contact, normal and tangent)
    /// into it, and keeps them.
    pub(crate) fn store_from(&mut self, contacts: &mut [Contact], impulses: &[(f64, f64)]) {
        self.entries.clear();
        self.entries.extend(
            contacts
                .iter_mut()
                .zip(impulses)
                .map(|(c, &(normal, tangent))| {
                    (c.normal_impulse, c.tangent_impulse) = (normal, tangent);
                    (key(c), normal, tangent)
                }),
        );
    }

    /// Keeps the impulses the solve wrote into `contacts`.
    pub(crate) fn store(&mut self, contacts: &[Contact]) {
        self.entries.clear();
        self.entries.extend(
            contacts
                .iter()
                .map(|c| (key(c), c.normal_impulse, c.tangent_impulse)),
        );
    }

    /// The last impulses of `contact`, the `k`-th of this step's contacts, if the `k`-th
    /// entry is its own, as it is where no contact came or went before it, or if one of
    /// its neighbours is: a manifold's two points may come in the other order than last
    /// step's (a big pile at rest has such a swap somewhere in many of its steps, and a
    /// miss costs a `recall` of every contact). A key is a contact's alone, so the
    /// entry found is the one `recall` finds. `None` says only that this guess missed
    /// (`recall` finds them all).
    #[inline]
    pub(crate) fn guess(&self, k: usize, contact: &Contact) -> Option<(f64, f64)> {
        let key = key(contact);
        let own = |m: &&Entry| m.0 == key;
        let m = [k, k + 1, k.wrapping_sub(1)]
            .into_iter()
            .find_map(|j| self.entries.get(j).filter(own))?;
        Some((m.1, m.2))
    }

    /// Each contact's last (normal, tangent) impulses, zeros for a new one, into `out` in
    /// the order of `contacts`.
    ///
    /// Both lists come by body pair in increasing order, and most contacts are the last
    /// step's: each is looked for first where the last one's search ended (after the
    /// entry found), then among its pair's entries, found a few entries on or else by a
    /// binary search. (Searched for contact by contact, in the islands' order, the smash's
    /// contacts, which come and go, spent a quarter of building their points searching.)
    pub(crate) fn recall(&self, contacts: &[Contact], out: &mut Vec<(f64, f64)>) {
        /// How far on a pair's entries are looked for before a binary search.
        const SCAN: usize = 8;
        out.clear();
        let entries = &self.entries;
        let pair_of = |m: &Entry| (m.0.0, m.0.1);
        // The entry after the last one found, and the last pair's first entry (or where it
        // would be).
        let mut next = 0;
        let mut run: Option<((u32, u32), usize)> = None;
        out.extend(contacts.iter().map(|c| {
            let key = key(c);
            if let Some(m) = entries.get(next).filter(|m| m.0 == key) {
                next += 1;
                return (m.1, m.2);
            }
            let pair = (key.0, key.1);
            let start = match run {
                Some((last, start)) if last == pair => start,
                _ => {
                    // If the entry before `next` is of a lower pair, so is every one
                    // before it (the entries are sorted), and the pair starts at or after
                    // `next`; else (a pair out of order) anywhere.
                    let from = if next == 0 || pair_of(&entries[next - 1]) < pair {
                        next
                    } else {
                        0
                    };
                    let rest = &entries[from..];
                    let offset = match rest.iter().take(SCAN).position(|m| pair_of(m) >= pair) {
                        Some(offset) => offset,
                        None => rest.partition_point(|m| pair_of(m) < pair),
                    };
                    from + offset
                }
            };
            run = Some((pair, start));
            let found = entries[start..]
                .iter()
                .take_while(|m| pair_of(m) == pair)
                .position(|m| m.0.2 == key.2);
            match found {
                Some(offset) => {
                    next = start + offset + 1;
                    (entries[next - 1].1, entries[next - 1].2)
                }
                None => {
                    next = start;
                    (0.0, 0.0)
                }
            }
        }));
    }
}

/// A remembered contact: ((body A, body B, feature), normal impulse, tangent impulse).
type Entry = ((u32, u32, u32), f64, f64);

/// What a contact is remembered by: its bodies and its feature.
fn key(c: &Contact) -> (u32, u32, u32) {
    (c.body_a.0, c.body_b.0, c.id.0)
}

/// One contact point between bodies `a` and `b`, with its material and its last impulses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Contact {
    pub body_a: BodyHandle,
    pub body_b: BodyHandle,
    pub point: Vec2,
    /// Unit normal from B towards A (thesis §2.4).
    pub normal: Vec2,
    /// Penetration depth (negative inside the contact margin).
    pub depth: f64,
    pub id: FeatureId,
    /// Combined coefficient of restitution e (thesis §6.4: the minimum of the two).
    pub restitution: f64,
    /// Combined friction coefficient μ.
    pub friction: f64,
    /// Normal relative velocity at the start of the step, before forces acted. Restitution
    /// reflects this one: reflecting the velocity after this step's gravity kick would add
    /// g·h·v of energy per bounce (5% of the height at h = 1/60 s).
    pub approach_velocity: f64,
    /// Normal relative velocity when the contact was found (after this step's forces).
    pub normal_velocity: f64,
    /// Impulse `j` along `normal` applied to A (and −j to B) by the last solve.
    pub normal_impulse: f64,
    /// Impulse `t` along `normal⊥` applied to A (and −t to B) by the last solve.
    pub tangent_impulse: f64,
}

impl Contact {
    /// Whether the bodies meet during this step: touching already, or closing the gap.
    pub(crate) fn meets_this_step(&self, dt: f64) -> bool {
        let gap = -self.depth;
        gap <= 0.0 || -self.normal_velocity * dt > gap
    }

    /// Whether the contact bounces: it meets this step, fast enough (thesis §6.4).
    pub(crate) fn bounces(&self, dt: f64, bounce_below: f64) -> bool {
        self.restitution > 0.0
            && self.meets_this_step(dt)
            && -self.approach_velocity >= bounce_below
    }

    /// The least normal velocity (B to A) the contact allows after this step's solve: a
    /// bounce reflects the approach (eq. 19), bodies still apart may close the gap and no
    /// further, touching bodies may not approach. (Stopping apart bodies where they are
    /// would leave a body hovering up to g·h² above the ground: 3 mm at 60 Hz, three body
    /// sizes for a 1 mm part.)
    pub(crate) fn min_normal_velocity(&self, dt: f64, bounce_below: f64) -> f64 {
        if self.bounces(dt, bounce_below) {
            -self.restitution * self.approach_velocity.min(0.0)
        } else if self.depth < 0.0 {
            self.depth / dt
        } else {
            0.0
        }
    }

    pub(crate) fn tangent(&self) -> Vec2 {
        perp(self.normal)
    }

    /// Velocity of A's point relative to B's, `v_AB` (thesis eq. 2–3).
    pub(crate) fn relative_velocity(&self, bodies: &[SolverBody]) -> Vec2 {
        let (a, b) = (&bodies[self.body_a.index()], &bodies[self.body_b.index()]);
        a.velocity_at(self.point) - b.velocity_at(self.point)
    }

    /// Velocity change along `d_out` at this contact from a unit impulse along `d_in` at
    /// `other` (+ on A, − on B): one entry of the thesis's `A_il` with signs (§3.2.2).
    pub(crate) fn coupling(
        &self,
        d_out: Vec2,
        other: &Contact,
        d_in: Vec2,
        bodies: &[SolverBody],
    ) -> f64 {
        let mut sum = 0.0;
        for (body, s_out) in [(self.body_a, 1.0), (self.body_b, -1.0)] {
            for (other_body, s_in) in [(other.body_a, 1.0), (other.body_b, -1.0)] {
                if body == other_body {
                    let t = &bodies[body.index()];
                    let r_out = self.point - t.position;
                    let r_in = other.point - t.position;
                    sum += s_out
                        * s_in
                        * (t.inv_mass * d_out.dot(&d_in)
                            + t.inv_inertia * cross(r_out, d_out) * cross(r_in, d_in));
                }
            }
        }
        sum
    }

    /// Applies `j·n + t·n⊥` to A at the contact point and the opposite to B.
    pub(crate) fn apply(
        &self,
        bodies: &mut [SolverBody],
        normal_impulse: f64,
        tangent_impulse: f64,
    ) {
        let impulse = self.normal * normal_impulse + self.tangent() * tangent_impulse;
        bodies[self.body_a.index()].apply_impulse(impulse, self.point);
        bodies[self.body_b.index()].apply_impulse(-impulse, self.point);
    }
}

/// Two bodies' friction coefficients mixed for their contacts: the geometric mean. Equal
/// coefficients (the usual case: both the world's) give that coefficient without a
/// square root, with the same bits: in binary floating point sqrt(f·f) rounds to f.
pub(crate) fn mixed_friction(a: f64, b: f64) -> f64 {
    if a == b { a } else { geometric_mean(a, b) }
}

/// Out of line, so that the compiler keeps the branch above: inlined, it computed the
/// root for every contact and chose after, the stall it was meant to skip.
#[cold]
#[inline(never)]
fn geometric_mean(a: f64, b: f64) -> f64 {
    (a * b).sqrt()
}

/// The speed below which contacts do not bounce: resting bodies would otherwise hop on the
/// velocity gravity adds in one step (thesis §6.4).
pub(crate) fn restitution_threshold(gravity: Vec2, dt: f64) -> f64 {
    2.0 * gravity.norm() * dt
}

/// thesis §2.4.5's "separated" impulses: each contact alone, once, in order (eq. 15 and
/// Coulomb friction of §2.4.4). Poor with several contacts — kept as the baseline the
/// simultaneous solvers are measured against.
pub(crate) fn solve_sequential(
    contacts: &mut [Contact],
    bodies: &mut [SolverBody],
    dt: f64,
    bounce_below: f64,
) {
    for c in contacts.iter_mut() {
        let v = c.relative_velocity(bodies);
        let v_n = v.dot(&c.normal);
        let mut target = c.min_normal_velocity(dt, bounce_below);
        if c.bounces(dt, bounce_below) {
            // The approach was read at the step's start; a contact solved before this one
            // may have slowed it since. Leaving faster than it now meets would add energy.
            target = target.min((-v_n).max(0.0));
        }
        if v_n >= target {
            c.normal_impulse = 0.0;
            c.tangent_impulse = 0.0;
            continue;
        }
        let k_n = c.coupling(c.normal, c, c.normal, bodies);
        let j = (target - v_n) / k_n;
        let t_dir = c.tangent();
        let k_t = c.coupling(t_dir, c, t_dir, bodies);
        let v_t = v.dot(&t_dir) + j * c.coupling(t_dir, c, c.normal, bodies);
        let t = clamp(-v_t / k_t, -c.friction * j, c.friction * j);
        c.apply(bodies, j, t);
        c.normal_impulse = j;
        c.tangent_impulse = t;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `mixed_friction` skips the square root for equal coefficients on the claim that
    /// sqrt(f·f) is f to the bit: checked over a spread of coefficients, from tiny to
    /// absurd, including every one a user types with two decimals.
    #[test]
    fn equal_frictions_mix_to_the_same_bits_as_the_square_root_gives() {
        let typed = (0..=1000).map(|k| k as f64 / 100.0);
        let spread = (0..2000).map(|k| 1e-6 * 1.0137_f64.powi(k));
        for f in typed.chain(spread) {
            assert_eq!(
                mixed_friction(f, f).to_bits(),
                (f * f).sqrt().to_bits(),
                "{f}"
            );
        }
        assert_eq!(mixed_friction(0.25, 1.0), 0.5);
    }

    /// Contacts of the given (body A, body B, feature), the k-th with impulses
    /// (`impulse + k`, `-impulse - k`).
    fn contacts(keys: &[(u32, u32, u32)], impulse: f64) -> Vec<Contact> {
        keys.iter()
            .enumerate()
            .map(|(k, &(a, b, id))| Contact {
                body_a: BodyHandle(a),
                body_b: BodyHandle(b),
                point: Vec2::zeros(),
                normal: Vec2::new(0.0, 1.0),
                depth: 0.0,
                id: FeatureId(id),
                restitution: 0.0,
                friction: 0.5,
                approach_velocity: 0.0,
                normal_velocity: 0.0,
                normal_impulse: impulse + k as f64,
                tangent_impulse: -impulse - k as f64,
            })
            .collect()
    }

    /// Each of `now`'s impulses in `last`, found by a search of all of it: what
    /// `ContactMemory::recall` must give.
    fn searched(last: &[Contact], now: &[Contact]) -> Vec<(f64, f64)> {
        now.iter()
            .map(|c| {
                last.iter()
                    .find(|m| (m.body_a, m.body_b, m.id) == (c.body_a, c.body_b, c.id))
                    .map_or((0.0, 0.0), |m| (m.normal_impulse, m.tangent_impulse))
            })
            .collect()
    }

    /// Every contact finds its own last impulses and a new one zeros, as a search of the
    /// whole memory finds them: contacts gone, come, reordered within a pair, and a pair
    /// out of order.
    #[test]
    fn recall_finds_each_contacts_last_impulses() {
        let last = contacts(
            &[
                (0, 1, 7),
                (0, 1, 9),
                (0, 4, 1),
                (2, 3, 5),
                (2, 5, 1),
                (2, 5, 2),
                (6, 8, 3),
            ],
            10.0,
        );
        let mut memory = ContactMemory::default();
        memory.store(&last);
        let now = contacts(
            &[
                (0, 1, 9),
                (0, 1, 7),
                (0, 2, 1), // a new pair
                (2, 5, 2),
                (2, 3, 5), // out of order
                (2, 5, 1),
                (2, 5, 3), // a new feature of a pair kept
                (6, 8, 3),
                (7, 9, 1), // past every entry
            ],
            0.0,
        );
        let mut recalled = vec![];
        memory.recall(&now, &mut recalled);
        assert_eq!(recalled, searched(&last, &now));
        let found = recalled.iter().filter(|r| r.0 != 0.0).count();
        assert_eq!(found, 6, "{recalled:?}");
        memory.recall(&[], &mut recalled);
        assert!(recalled.is_empty());
    }

    /// A guess finds a contact's entry at its own index or beside it (a manifold's two
    /// points the other way round), with the impulses a search finds, and misses
    /// anything further off or new.
    #[test]
    fn a_guess_finds_a_manifolds_points_in_either_order() {
        let last = contacts(
            &[(0, 1, 7), (0, 1, 9), (2, 3, 1), (2, 3, 4), (5, 6, 2)],
            10.0,
        );
        let mut memory = ContactMemory::default();
        memory.store(&last);
        let now = contacts(
            &[(0, 1, 9), (0, 1, 7), (2, 3, 4), (2, 3, 1), (5, 6, 2)],
            0.0,
        );
        let guessed: Vec<_> = (0..now.len()).map(|k| memory.guess(k, &now[k])).collect();
        let searched: Vec<_> = searched(&last, &now).into_iter().map(Some).collect();
        assert_eq!(guessed, searched);
        // Two entries off (a contact gone before it), and a contact not in the memory.
        let shifted = contacts(&[(2, 3, 1), (2, 3, 4), (5, 6, 2), (7, 8, 1)], 0.0);
        assert_eq!(memory.guess(0, &shifted[2]), None);
        assert_eq!(memory.guess(3, &shifted[3]), None);
        assert_eq!(memory.guess(7, &shifted[2]), None);
        // Past the last entry, beside it.
        assert_eq!(memory.guess(5, &shifted[2]), searched[4]);
    }

    /// The same over thousands of contacts: many gone and many new (pairs skipped over by
    /// more than the scan, so found by the binary search), the rest kept, each pair's
    /// features in either order, and now and then two pairs out of order.
    #[test]
    fn recall_finds_each_contacts_last_impulses_through_churn() {
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = move |below: u64| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed % below
        };
        let keys = |next: &mut dyn FnMut(u64) -> u64, pairs: u32| {
            let mut keys = vec![];
            for a in 0..pairs {
                let b = a + 1 + next(3) as u32;
                for id in 0..next(3) as u32 {
                    keys.push((a, b, id));
                }
            }
            keys
        };
        let last_keys = keys(&mut next, 3000);
        let last = contacts(&last_keys, 1.0);
        let mut memory = ContactMemory::default();
        memory.store(&last);
        // A quarter gone, runs of pairs gone (longer than the scan), new pairs and new
        // features of pairs kept.
        let new_pairs = keys(&mut next, 3000);
        let mut now_keys: Vec<(u32, u32, u32)> = last_keys
            .iter()
            .copied()
            .filter(|k| next(4) != 0 && k.0 % 200 >= 30)
            .chain(new_pairs.into_iter().map(|(a, b, id)| (a, b + 3, id)))
            .chain((0..3000).step_by(5).map(|a| (a, a + 1, 7)))
            .collect();
        now_keys.sort_by_key(|&(a, b, _)| (a, b));
        for k in 1..now_keys.len() {
            let pair = |k: usize| (now_keys[k].0, now_keys[k].1);
            if pair(k - 1) == pair(k) && next(2) == 0 {
                now_keys.swap(k - 1, k); // a pair's features the other way round
            }
        }
        for k in (50..now_keys.len()).step_by(97) {
            now_keys.swap(k - 1, k); // pairs out of order
        }
        let now = contacts(&now_keys, 0.0);
        let mut recalled = vec![];
        memory.recall(&now, &mut recalled);
        assert_eq!(recalled, searched(&last, &now));
        let found = recalled.iter().filter(|r| r.0 != 0.0).count();
        assert!(
            found > 1000 && found < now.len() - 1000,
            "{found} of {}",
            now.len()
        );
    }
}

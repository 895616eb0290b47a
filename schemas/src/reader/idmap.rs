//! [`IdMap`]: the reader's tables keyed by an MCAP channel id (`u16`), looked up once or more for
//! every message. A `BTreeMap<u16, T>` costs a search per lookup (about 5 % of `analyze
//! summary`'s profile, issue 24 item 5); this map finds an id through a table of positions
//! indexed by the id itself and keeps its entries in ascending id order, so that iterating it
//! gives what the `BTreeMap` gave.
//!
//! Memory: the entries, plus 4 bytes per id up to the largest id inserted (at most 256 KiB for
//! id 65 535, whatever the file holds).

/// No entry for this id.
const NONE: u32 = u32::MAX;

/// A map from `u16` ids to `T`, iterated in ascending id order (the subset of `BTreeMap`'s API
/// the reader uses).
#[derive(Debug, Clone)]
pub(crate) struct IdMap<T> {
    /// Position in `entries` of each id (`NONE`: absent), indexed by id.
    position: Vec<u32>,
    /// The entries, ascending by id.
    entries: Vec<(u16, T)>,
}

impl<T> Default for IdMap<T> {
    fn default() -> Self {
        IdMap { position: Vec::new(), entries: Vec::new() }
    }
}

impl<T> IdMap<T> {
    fn slot(&self, id: u16) -> Option<usize> {
        self.position.get(usize::from(id)).copied().filter(|&p| p != NONE).map(|p| p as usize)
    }

    /// The table of positions after `entries` changed (rare: a new channel, a restore).
    fn reindex(&mut self) {
        self.position.iter_mut().for_each(|p| *p = NONE);
        for (k, (id, _)) in self.entries.iter().enumerate() {
            let i = usize::from(*id);
            if self.position.len() <= i {
                self.position.resize(i + 1, NONE);
            }
            self.position[i] = k as u32;
        }
    }

    pub(crate) fn get(&self, id: &u16) -> Option<&T> {
        self.slot(*id).map(|k| &self.entries[k].1)
    }

    pub(crate) fn get_mut(&mut self, id: &u16) -> Option<&mut T> {
        self.slot(*id).map(|k| &mut self.entries[k].1)
    }

    /// Inserts `value` at `id`; the value it replaces, if any.
    pub(crate) fn insert(&mut self, id: u16, value: T) -> Option<T> {
        if let Some(k) = self.slot(id) {
            return Some(std::mem::replace(&mut self.entries[k].1, value));
        }
        let at = self.entries.partition_point(|(i, _)| *i < id);
        self.entries.insert(at, (id, value));
        self.reindex();
        None
    }

    /// Keeps the entries for which `keep` is true.
    pub(crate) fn retain(&mut self, mut keep: impl FnMut(&u16, &mut T) -> bool) {
        self.entries.retain_mut(|(id, v)| keep(id, v));
        self.reindex();
    }

    pub(crate) fn iter(&self) -> impl Iterator<Item = (&u16, &T)> {
        self.entries.iter().map(|(id, v)| (id, v))
    }

    pub(crate) fn into_values(self) -> impl Iterator<Item = T> {
        self.entries.into_iter().map(|(_, v)| v)
    }
}

impl<'a, T> IntoIterator for &'a mut IdMap<T> {
    type Item = (&'a u16, &'a mut T);
    type IntoIter = std::iter::Map<std::slice::IterMut<'a, (u16, T)>, fn(&'a mut (u16, T)) -> (&'a u16, &'a mut T)>;
    fn into_iter(self) -> Self::IntoIter {
        self.entries.iter_mut().map(|(id, v)| (&*id, v))
    }
}

impl<T> std::ops::Index<&u16> for IdMap<T> {
    type Output = T;
    fn index(&self, id: &u16) -> &T {
        self.get(id).expect("IdMap: no entry for this id")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    /// The same answers and the same iteration order as a `BTreeMap` over a sequence of inserts
    /// (new and replacing), lookups and retains, ids from 0 to 65 535.
    #[test]
    fn behaves_as_a_btreemap() {
        let mut a: IdMap<u64> = IdMap::default();
        let mut b: BTreeMap<u16, u64> = BTreeMap::new();
        let ids = [7u16, 3, 65535, 0, 3, 12, 40000, 7, 1, 2];
        for (k, &id) in ids.iter().enumerate() {
            assert_eq!(a.insert(id, k as u64), b.insert(id, k as u64));
            for probe in [0u16, 1, 2, 3, 4, 7, 12, 13, 40000, 65534, 65535] {
                assert_eq!(a.get(&probe), b.get(&probe));
            }
            assert!(a.iter().map(|(i, v)| (*i, *v)).eq(b.iter().map(|(i, v)| (*i, *v))));
        }
        *a.get_mut(&12).unwrap() += 100;
        *b.get_mut(&12).unwrap() += 100;
        a.retain(|id, _| id % 2 == 1);
        b.retain(|id, _| id % 2 == 1);
        for (_, v) in &mut a {
            *v += 1;
        }
        for v in b.values_mut() {
            *v += 1;
        }
        assert!(a.iter().map(|(i, v)| (*i, *v)).eq(b.iter().map(|(i, v)| (*i, *v))));
        assert_eq!(a[&7], b[&7]);
        assert_eq!(a.get(&12), None);
        assert!(a.into_values().eq(b.into_values()));
    }
}

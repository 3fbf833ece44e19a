//! Dependency sets: which symbols a node depends on, as bitsets.
//!
//! Every node of the graph carries one, computed at interning time as the
//! union of its children's, so questions such as "does coordinate x1 appear
//! anywhere in B, b, β̄, γ̄ or F" (the cyclic-coordinate test of Sec. III C)
//! are a few word operations.

use crate::handles::Symbol;

/// A set of symbols.
///
/// ```
/// use appell_symbolic::{Graph, SymbolSet};
/// let mut g = Graph::new();
/// let x = g.parameter("x").unwrap();
/// let y = g.parameter("y").unwrap();
/// let mut s = SymbolSet::new();
/// s.insert(y);
/// assert!(s.contains(y) && !s.contains(x));
/// assert_eq!(s.iter().collect::<Vec<_>>(), vec![y]);
/// ```
#[derive(Clone, Debug, Default, PartialEq, Eq, Hash)]
pub struct SymbolSet {
    words: Vec<u64>,
}

impl SymbolSet {
    /// The empty set.
    pub fn new() -> SymbolSet {
        SymbolSet { words: Vec::new() }
    }

    /// The set holding one symbol.
    pub fn single(s: Symbol) -> SymbolSet {
        let mut set = SymbolSet::new();
        set.insert(s);
        set
    }

    /// A set from symbols.
    pub fn from_symbols(symbols: impl IntoIterator<Item = Symbol>) -> SymbolSet {
        let mut set = SymbolSet::new();
        for s in symbols {
            set.insert(s);
        }
        set
    }

    /// Adds a symbol.
    pub fn insert(&mut self, s: Symbol) {
        let (w, b) = (s.index() / 64, s.index() % 64);
        if self.words.len() <= w {
            self.words.resize(w + 1, 0);
        }
        self.words[w] |= 1 << b;
    }

    /// Whether the set holds `s`.
    pub fn contains(&self, s: Symbol) -> bool {
        let (w, b) = (s.index() / 64, s.index() % 64);
        self.words.get(w).is_some_and(|x| x & (1 << b) != 0)
    }

    /// Adds every symbol of `other`.
    pub fn union_with(&mut self, other: &SymbolSet) {
        if self.words.len() < other.words.len() {
            self.words.resize(other.words.len(), 0);
        }
        for (a, b) in self.words.iter_mut().zip(&other.words) {
            *a |= b;
        }
    }

    /// Whether the two sets share a symbol.
    pub fn intersects(&self, other: &SymbolSet) -> bool {
        self.words.iter().zip(&other.words).any(|(a, b)| a & b != 0)
    }

    /// Whether every symbol of `self` is in `other`.
    pub fn is_subset(&self, other: &SymbolSet) -> bool {
        self.words
            .iter()
            .enumerate()
            .all(|(i, a)| a & !other.words.get(i).copied().unwrap_or(0) == 0)
    }

    /// Whether the set is empty.
    pub fn is_empty(&self) -> bool {
        self.words.iter().all(|w| *w == 0)
    }

    /// Number of symbols in the set.
    pub fn len(&self) -> usize {
        self.words.iter().map(|w| w.count_ones() as usize).sum()
    }

    /// The symbols in increasing order.
    pub fn iter(&self) -> impl Iterator<Item = Symbol> + '_ {
        self.words.iter().enumerate().flat_map(|(i, &w)| {
            (0..64)
                .filter(move |b| w & (1u64 << b) != 0)
                .map(move |b| Symbol((i * 64 + b) as u32))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn s(i: u32) -> Symbol {
        Symbol(i)
    }

    #[test]
    fn insert_beyond_first_word() {
        let mut a = SymbolSet::new();
        a.insert(s(130));
        assert!(a.contains(s(130)) && !a.contains(s(2)));
    }
    #[test]
    fn union_and_intersects() {
        let mut a = SymbolSet::single(s(1));
        let b = SymbolSet::single(s(70));
        assert!(!a.intersects(&b));
        a.union_with(&b);
        assert!(a.intersects(&b));
    }
    #[test]
    fn subset_with_different_lengths() {
        let a = SymbolSet::single(s(3));
        let b = SymbolSet::from_symbols([s(3), s(100)]);
        assert!(a.is_subset(&b) && !b.is_subset(&a));
    }
    #[test]
    fn iter_sorted() {
        let a = SymbolSet::from_symbols([s(65), s(0), s(7)]);
        assert_eq!(a.iter().collect::<Vec<_>>(), vec![s(0), s(7), s(65)]);
        assert_eq!(a.len(), 3);
    }
}

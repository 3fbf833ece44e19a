//! Handles: the small copyable indices by which nodes and symbols of a
//! [`Graph`](crate::Graph) are named. They live apart from the graph so that
//! the modules the graph is built on (symbol sets, say) can name them
//! without depending on the graph.

/// The handle of a node in a [`Graph`](crate::Graph). Equal ids mean equal expressions.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Id(pub u32);

impl Id {
    /// The position of the node in the arena.
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// The handle of a symbol declared in a [`Graph`](crate::Graph).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Symbol(pub(crate) u32);

impl Symbol {
    /// The position of the symbol in the graph's symbol table.
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

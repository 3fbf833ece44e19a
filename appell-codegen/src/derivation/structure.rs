//! Structure of sparse square systems: which entries can be non-zero.
//!
//! The elimination's numeric part S X = R is mostly zeros in real
//! mechanisms. A matching of rows to unknowns shows a system that no value
//! of the parameters can make solvable; rows with a single unknown left are
//! solved one by one (the generated code does the same, see
//! [`singleton_rows`]); and X is zero wherever S and R force it.

use appell_symbolic::{Graph, Id, SymMatrix};

/// The order in which a square system S x = r is solved when rows with a
/// single entry among the unknowns not yet solved go first, one by one
/// (see [`singleton_rows`]).
pub struct SingletonOrder {
    /// (row, unknown) pairs, in solving order.
    pub peeled: Vec<(usize, usize)>,
    /// The rows left to a dense solve, in order.
    pub rows_left: Vec<usize>,
    /// The unknowns left to a dense solve, in order.
    pub cols_left: Vec<usize>,
}

/// Rows of a k×k matrix with a single nonzero entry among the unknowns not
/// yet solved, peeled in order (each solved by one division; no other
/// entry changes, so there is nothing for pivoting to protect); `entry`
/// says whether an entry can be nonzero. The generated code and
/// `structural_solution` both follow this order.
///
/// ```
/// use appell_codegen::derivation::singleton_rows;
/// // Row 0 reads only unknown 1; then rows 1 and 2 share unknowns 0 and 2.
/// let nonzero = [[false, true, false], [true, true, true], [true, false, true]];
/// let order = singleton_rows(3, |i, j| nonzero[i][j]);
/// assert_eq!(order.peeled, vec![(0, 1)]);
/// assert_eq!((order.rows_left, order.cols_left), (vec![1, 2], vec![0, 2]));
/// ```
pub fn singleton_rows(k: usize, entry: impl Fn(usize, usize) -> bool) -> SingletonOrder {
    let mut rows_left: Vec<usize> = (0..k).collect();
    let mut cols_left: Vec<usize> = (0..k).collect();
    let mut peeled = Vec::new();
    while let Some((at, col)) = rows_left.iter().enumerate().find_map(|(at, &i)| {
        let mut found = cols_left.iter().filter(|&&j| entry(i, j));
        match (found.next(), found.next()) {
            (Some(&j), None) => Some((at, j)),
            _ => None,
        }
    }) {
        let row = rows_left.remove(at);
        cols_left.retain(|&j| j != col);
        peeled.push((row, col));
    }
    SingletonOrder {
        peeled,
        rows_left,
        cols_left,
    }
}

/// Which entries of X in S X = R can be nonzero, from where S and R are
/// identically zero: rows of S with a single entry among the unknowns not
/// yet solved are solved one by one (as the generated code does), and an
/// unknown so solved is zero in a column where its row of R and every
/// earlier unknown its row reads are zero; the unknowns of the remaining
/// block are taken as nonzero wherever the block's right side can be. (The
/// bicycle's pitch rate does not depend on the rear wheel's rate.)
pub fn structural_solution(
    g: &Graph,
    s: &SymMatrix,
    r: &SymMatrix,
    k: usize,
    width: usize,
) -> Vec<Vec<bool>> {
    let entry = |i: usize, j: usize| !g.is_zero(s[(i, j)]);
    let order = singleton_rows(k, entry);
    let mut nonzero = vec![vec![true; width]; k];
    for (t, &(row, col)) in order.peeled.iter().enumerate() {
        for c in 0..width {
            nonzero[col][c] = !g.is_zero(r[(row, c)])
                || order.peeled[..t]
                    .iter()
                    .any(|&(_, jj)| entry(row, jj) && nonzero[jj][c]);
        }
    }
    let (rows_left, cols_left) = (&order.rows_left, &order.cols_left);
    let peeled: Vec<usize> = order.peeled.iter().map(|&(_, j)| j).collect();
    for c in 0..width {
        let block = rows_left.iter().any(|&row| {
            !g.is_zero(r[(row, c)]) || peeled.iter().any(|&jj| entry(row, jj) && nonzero[jj][c])
        });
        for &j in cols_left {
            nonzero[j][c] = block;
        }
    }
    nonzero
}

/// A column (unknown rate) of the square system that no row can be matched to, by
/// augmenting paths over the non-zero pattern.
pub fn unmatched_column(g: &Graph, a: &[Id], size: usize) -> Option<usize> {
    let nonzero = |r: usize, c: usize| !g.is_zero(a[r * size + c]);
    let mut row_of_col: Vec<Option<usize>> = vec![None; size];
    fn augment(
        r: usize,
        seen: &mut [bool],
        row_of_col: &mut [Option<usize>],
        size: usize,
        nonzero: &dyn Fn(usize, usize) -> bool,
    ) -> bool {
        for c in 0..size {
            if nonzero(r, c) && !seen[c] {
                seen[c] = true;
                if row_of_col[c].is_none_or(|r2| augment(r2, seen, row_of_col, size, nonzero)) {
                    row_of_col[c] = Some(r);
                    return true;
                }
            }
        }
        false
    }
    for r in 0..size {
        let mut seen = vec![false; size];
        augment(r, &mut seen, &mut row_of_col, size, &nonzero);
    }
    row_of_col.iter().position(|x| x.is_none())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn structural_solution_follows_the_singleton_rows() {
        let mut g = Graph::new();
        // Row 0 has one entry (column 1): x1 = r0 / a, zero where r0 is.
        // The block (rows 1, 2; columns 0, 2) is then dense: its unknowns
        // are nonzero where any of its rows' right sides, or x1 through
        // the entries b and e, can be.
        let s = SymMatrix::parse(
            &mut g,
            &[&["0", "a", "0"], &["c", "b", "d"], &["f", "0", "h"]],
        )
        .unwrap();
        let r = SymMatrix::parse(
            &mut g,
            &[&["p", "0", "0"], &["0", "0", "0"], &["0", "0", "q"]],
        )
        .unwrap();
        let nz = structural_solution(&g, &s, &r, 3, 3);
        assert_eq!(nz[1], vec![true, false, false]);
        // Column 0 reaches the block through b·x1; column 1 is zero
        // throughout; column 2 through q.
        assert_eq!(nz[0], vec![true, false, true]);
        assert_eq!(nz[2], vec![true, false, true]);
    }
}

#[cfg(test)]
mod matching_tests {
    use super::*;

    #[test]
    fn an_unknown_no_row_can_be_matched_to_is_found() {
        let mut g = Graph::new();
        // Rows 0 and 1 both read only unknown 0: unknown 1 has no row.
        let a: Vec<Id> = ["a", "0", "b", "0"]
            .iter()
            .map(|t| g.parse(t).unwrap())
            .collect();
        assert_eq!(unmatched_column(&g, &a, 2), Some(1));
        let a: Vec<Id> = ["0", "a", "b", "c"]
            .iter()
            .map(|t| g.parse(t).unwrap())
            .collect();
        assert_eq!(unmatched_column(&g, &a, 2), None);
    }
}

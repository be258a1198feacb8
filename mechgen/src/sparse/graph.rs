//! Graph algorithms on the Jacobian's sparsity pattern: a maximum matching of equations to the
//! coordinates they touch (shared by the structural check and the solve structure), and the
//! strongly connected components that order a square system block-triangularly.

/// Marks an equation or coordinate without a partner in a [`Matching`].
pub const UNMATCHED: usize = usize::MAX;

/// A maximum matching of equations (rows) to coordinates (columns).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Matching {
    /// The coordinate matched to each equation, or [`UNMATCHED`].
    pub row: Vec<usize>,
    /// The equation matched to each coordinate, or [`UNMATCHED`].
    pub column: Vec<usize>,
}

impl Matching {
    /// Number of matched pairs: the structural rank.
    pub fn size(&self) -> usize {
        self.row.iter().filter(|&&c| c != UNMATCHED).count()
    }

    /// True if every equation and every coordinate is matched.
    pub fn is_perfect(&self) -> bool {
        self.row.len() == self.column.len() && self.size() == self.row.len()
    }
}

/// A maximum matching of a pattern: `rows[i]` lists the coordinates (`< columns`) equation `i`
/// touches.
///
/// Augmenting paths from a greedy start, each search a depth-first walk with a look-ahead for a
/// free coordinate and visit stamps: O(equations × non-zeros) at worst, near linear on the
/// chains and trees of real mechanisms.
pub fn maximum_matching(rows: &[Vec<usize>], columns: usize) -> Matching {
    let mut row_match = vec![UNMATCHED; rows.len()];
    let mut col_match = vec![UNMATCHED; columns];
    for (r, cols) in rows.iter().enumerate() {
        if let Some(&c) = cols.iter().find(|&&c| col_match[c] == UNMATCHED) {
            row_match[r] = c;
            col_match[c] = r;
        }
    }
    let mut stamp = vec![0usize; columns];
    let mut stack: Vec<(usize, usize)> = Vec::new();
    for root in 0..rows.len() {
        if row_match[root] != UNMATCHED {
            continue;
        }
        let round = root + 1;
        stack.clear();
        stack.push((root, 0));
        let mut found = None;
        while let Some((row, next)) = stack.last_mut() {
            let row = *row;
            // Look-ahead: a free coordinate of this row ends the path at once.
            if *next == 0
                && let Some(&c) = rows[row].iter().find(|&&c| col_match[c] == UNMATCHED)
            {
                found = Some(c);
                break;
            }
            match rows[row].get(*next) {
                Some(&c) => {
                    *next += 1;
                    if stamp[c] != round {
                        stamp[c] = round;
                        stack.push((col_match[c], 0));
                    }
                }
                None => {
                    stack.pop();
                }
            }
        }
        // Flip the path: the top row takes the free coordinate, every row below it the
        // coordinate through which the walk left it.
        if let Some(mut c) = found {
            while let Some((row, _)) = stack.pop() {
                row_match[row] = c;
                col_match[c] = row;
                if let Some(&(below, next)) = stack.last() {
                    c = rows[below][next - 1];
                }
            }
        }
    }
    Matching {
        row: row_match,
        column: col_match,
    }
}

/// The strongly connected components of the directed graph on `0..n` whose edges leave node `v`
/// towards `successors(v)`, each component's nodes ascending, components ordered so that every
/// edge leads to the same or an earlier component (Tarjan's algorithm, iterative).
///
/// For a square system with a perfect matching, with an edge from equation `i` to the equation
/// matched to each other coordinate `i` touches, this is the block-triangular order: every
/// block's equations read only coordinates of its own and earlier blocks.
pub fn strongly_connected_components<'a>(
    n: usize,
    successors: impl Fn(usize) -> &'a [usize],
) -> Vec<Vec<usize>> {
    const UNSEEN: usize = usize::MAX;
    let mut index = vec![UNSEEN; n];
    let mut low = vec![0usize; n];
    let mut on_stack = vec![false; n];
    let mut stack: Vec<usize> = Vec::new();
    let mut components = Vec::new();
    let mut counter = 0;
    // The depth-first walk: (node, position in its successor list).
    let mut walk: Vec<(usize, usize)> = Vec::new();
    for root in 0..n {
        if index[root] != UNSEEN {
            continue;
        }
        walk.push((root, 0));
        index[root] = counter;
        low[root] = counter;
        counter += 1;
        stack.push(root);
        on_stack[root] = true;
        while let Some(&mut (v, ref mut next)) = walk.last_mut() {
            if let Some(&w) = successors(v).get(*next) {
                *next += 1;
                if index[w] == UNSEEN {
                    index[w] = counter;
                    low[w] = counter;
                    counter += 1;
                    stack.push(w);
                    on_stack[w] = true;
                    walk.push((w, 0));
                } else if on_stack[w] {
                    low[v] = low[v].min(index[w]);
                }
                continue;
            }
            walk.pop();
            if let Some(&(parent, _)) = walk.last() {
                low[parent] = low[parent].min(low[v]);
            }
            if low[v] == index[v] {
                let mut component = Vec::new();
                while let Some(w) = stack.pop() {
                    on_stack[w] = false;
                    component.push(w);
                    if w == v {
                        break;
                    }
                }
                component.sort_unstable();
                components.push(component);
            }
        }
    }
    components
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matching_is_maximum_and_reports_unmatched_rows() {
        // Rows 0 and 1 both touch only column 0: one of them stays unmatched.
        let rows = vec![vec![0], vec![0], vec![1, 2]];
        let m = maximum_matching(&rows, 3);
        assert_eq!(m.size(), 2);
        assert!(!m.is_perfect());
        // A path that must be flipped: the greedy start takes column 0 for row 0.
        let rows = vec![vec![0, 1], vec![0]];
        let m = maximum_matching(&rows, 2);
        assert!(m.is_perfect());
        assert_eq!(m.row, vec![1, 0]);
    }

    #[test]
    fn components_come_in_dependency_order() {
        // 0 → 1 → 2 → 1 (cycle {1, 2}), 3 → 0: solve 1 and 2 together, then 0, then 3.
        let edges: Vec<Vec<usize>> = vec![vec![1], vec![2], vec![1], vec![0]];
        let components = strongly_connected_components(4, |v| &edges[v]);
        assert_eq!(components, vec![vec![1, 2], vec![0], vec![3]]);
    }

    #[test]
    fn a_long_chain_does_not_overflow_the_stack() {
        let n = 200_000;
        let edges: Vec<Vec<usize>> = (0..n)
            .map(|v| if v + 1 < n { vec![v + 1] } else { vec![] })
            .collect();
        let components = strongly_connected_components(n, |v| &edges[v]);
        assert_eq!(components.len(), n);
        // The last node depends on nothing: it comes first.
        assert_eq!(components[0], vec![n - 1]);
    }
}

//! The motor commands of a flight log: the same number of values on every row (one per rotor), kept
//! row after row in one buffer so that a long log holds no allocation per row.

use std::ops::Range;

/// At most this many motors a row (an octorotor, or four coaxial pairs).
pub const MAX_MOTORS: usize = 8;

/// The motor commands of every row: [`MotorCommands::count`] values a row.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MotorCommands {
    count: usize,
    values: Vec<f64>,
}

impl MotorCommands {
    /// No rows yet, `count` motors a row, room for `rows` rows.
    pub fn with_capacity(count: usize, rows: usize) -> Self {
        assert!(
            (1..=MAX_MOTORS).contains(&count),
            "1 to {MAX_MOTORS} motors, not {count}"
        );
        Self {
            count,
            values: Vec::with_capacity(count * rows),
        }
    }

    /// The rows given as arrays of `N` motors.
    pub fn from_rows<const N: usize>(rows: &[[f64; N]]) -> Self {
        rows.iter().copied().collect()
    }

    /// Appends a row; it must hold [`MotorCommands::count`] values.
    pub fn push(&mut self, row: &[f64]) {
        assert_eq!(row.len(), self.count, "a row of motor commands");
        self.values.extend_from_slice(row);
    }

    /// Motors a row.
    pub fn count(&self) -> usize {
        self.count
    }

    /// Rows.
    pub fn len(&self) -> usize {
        self.values.len().checked_div(self.count).unwrap_or(0)
    }

    /// Whether there are no rows.
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// Row `k`'s commands.
    pub fn row(&self, k: usize) -> &[f64] {
        &self.values[k * self.count..(k + 1) * self.count]
    }

    /// Row `k`'s commands, to change.
    pub fn row_mut(&mut self, k: usize) -> &mut [f64] {
        &mut self.values[k * self.count..(k + 1) * self.count]
    }

    /// The rows in order, to change.
    pub fn rows_mut(&mut self) -> std::slice::ChunksExactMut<'_, f64> {
        self.values.chunks_exact_mut(self.count.max(1))
    }

    /// Appends the rows of `other`, which has as many motors.
    pub fn extend(&mut self, other: &Self) {
        assert_eq!(other.count, self.count, "rows of as many motors");
        self.values.extend_from_slice(&other.values);
    }

    /// The rows in order.
    pub fn rows(&self) -> std::slice::ChunksExact<'_, f64> {
        self.values.chunks_exact(self.count.max(1))
    }

    /// The rows `rows` as commands of their own.
    pub fn range(&self, rows: Range<usize>) -> Self {
        Self {
            count: self.count,
            values: self.values[rows.start * self.count..rows.end * self.count].to_vec(),
        }
    }
}

impl<const N: usize> FromIterator<[f64; N]> for MotorCommands {
    fn from_iter<I: IntoIterator<Item = [f64; N]>>(rows: I) -> Self {
        let mut commands = Self::with_capacity(N, 0);
        for row in rows {
            commands.push(&row);
        }
        commands
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_come_back_as_they_were_pushed_whatever_the_motor_count() {
        let six = MotorCommands::from_rows(&[[1.0, 2.0, 3.0, 4.0, 5.0, 6.0], [7.0; 6]]);
        assert_eq!((six.count(), six.len()), (6, 2));
        assert_eq!(six.row(1), &[7.0; 6]);
        assert_eq!(six.range(1..2).rows().collect::<Vec<_>>(), vec![&[7.0; 6]]);
        assert!(MotorCommands::with_capacity(4, 10).is_empty());
    }
}

//! The command line: options, dispatch, progress and statistics.

pub fn main() -> i32 {
    0
}

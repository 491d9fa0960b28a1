//! "Did you mean": the known name closest to a misspelled one.

/// The candidate closest to `name` by edit distance, if it is close enough to be a likely typo.
pub fn closest_match<'b>(name: &str, candidates: &[&'b str]) -> Option<&'b str> {
    candidates
        .iter()
        .map(|c| (edit_distance(name, c), *c))
        .filter(|(d, c)| *d <= (c.len().max(name.len()) / 3).max(1))
        .min_by_key(|(d, _)| *d)
        .map(|(_, c)| c)
}

/// Levenshtein distance between two strings, counted in characters.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let substitution = diagonal + usize::from(ca != *cb);
            diagonal = row[j + 1];
            row[j + 1] = substitution.min(row[j] + 1).min(row[j + 1] + 1);
        }
    }
    row[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edit_distance_counts_single_edits() {
        assert_eq!(edit_distance("reflectance", "reflectance"), 0);
        assert_eq!(edit_distance("reflectanse", "reflectance"), 1);
        assert_eq!(edit_distance("fov", "fob"), 1);
        assert_eq!(edit_distance("", "abc"), 3);
    }

    #[test]
    fn closest_match_suggests_only_near_names() {
        let names = ["radiance", "reflectance", "max_depth"];
        assert_eq!(closest_match("reflectanse", &names), Some("reflectance"));
        assert_eq!(closest_match("maxdepth", &names), Some("max_depth"));
        assert_eq!(closest_match("colour", &names), None);
    }
}

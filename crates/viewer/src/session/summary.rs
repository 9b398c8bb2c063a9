//! The tree's one-line summary for the status bar.

use fourfold::tree::Touching;

use super::Session;

impl Session {
    /// A one-line summary of the tree for the status bar.
    pub fn tree_summary(&self) -> String {
        let Some(s) = &self.stats else {
            return "no tree yet".to_string();
        };
        if s.leaves == 0 {
            return "no surface in this domain (the tree kept no box)".to_string();
        }
        let mut line = format!("{} nodes, {} leaves", s.nodes, s.leaves);
        if let Some(cut) = self
            .marched
            .as_ref()
            .filter(|_| !self.scene.render.brute_force)
        {
            line.push_str(&format!(" (marched as {cut})"));
        }
        if s.budget_hit {
            line.push_str(", node budget hit (tree coarser than max level)");
        }
        if s.singular_boxes > 0 {
            line.push_str(&format!(", {} singular boxes", s.singular_boxes));
        }
        match s.touching() {
            Touching::Everywhere => {
                line.push_str(", F does not change sign (see the note over the picture)")
            }
            Touching::Partly => line.push_str(
                ", F does not change sign across part of M (see the note over the picture)",
            ),
            Touching::Nowhere => {}
        }
        line.push_str(&format!(", built in {:.0} ms", s.build_ms));
        line
    }
}

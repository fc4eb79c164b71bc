//! Wall leakage: how deep fluid gets behind the closed wall faces. Each
//! `/diagnostics` record carries one state's; the run keeps the worst over every
//! state it reads back (`RunReport::leakage`). The watchdog stops a run on its own
//! threshold (`Model::wall_stop_depth`), not on this tally.

use crate::model::Model;
use crate::state::State;

/// Fluid leaking into the wall layers: the deepest penetration behind a
/// closed wall face and how many fluid particles are more than ½Δx behind one.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Leakage {
    /// Deepest penetration behind a wall face, in Δx (0 with none).
    pub deepest_dx: f64,
    /// The particle (id) and face of the deepest penetration, and when.
    pub particle: Option<u32>,
    pub face: Option<(usize, usize)>,
    pub time: f64,
    /// Fluid particles more than ½Δx behind a wall face.
    pub beyond_half_dx: u64,
}

impl Leakage {
    /// The wall leakage of one state.
    pub fn of(m: &Model, st: &State) -> Leakage {
        let mut l = Leakage {
            time: st.sim.time as f64,
            ..Leakage::default()
        };
        for i in 0..st.active() {
            if !m.phases[st.phase[i] as usize].is_fluid() {
                continue;
            }
            let deepest = m
                .beyond_faces(m.to_world(st.pos[i]))
                .into_iter()
                .filter(|f| !f.3)
                .max_by(|x, y| x.2.total_cmp(&y.2));
            if let Some((a, side, d, _)) = deepest {
                let dx = d / m.dx;
                l.beyond_half_dx += (dx > 0.5) as u64;
                if dx > l.deepest_dx {
                    (l.deepest_dx, l.particle, l.face) = (dx, Some(st.id[i]), Some((a, side)));
                }
            }
        }
        l
    }

    /// Keep the deeper of two samples, and the larger count.
    pub fn absorb(&mut self, other: Leakage) {
        if other.deepest_dx > self.deepest_dx {
            let count = self.beyond_half_dx;
            *self = other;
            self.beyond_half_dx = count;
        }
        self.beyond_half_dx = self.beyond_half_dx.max(other.beyond_half_dx);
    }

    pub fn summary(&self) -> String {
        match (self.particle, self.face) {
            (Some(id), Some((a, side))) => format!(
                "deepest fluid penetration {:.2} dx (particle {id} behind the {} wall, t = {:.4e} s), at most {} particle(s) beyond 0.5 dx at once",
                self.deepest_dx,
                crate::scene::SIDE_NAMES[a][side],
                self.time,
                self.beyond_half_dx
            ),
            _ => "no fluid particle behind a wall face".into(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::PhaseKind;

    /// Penetration behind a closed face is measured in Δx, the deepest
    /// kept with its particle and face, and counted beyond ½Δx.
    #[test]
    fn leakage_measures_depth_behind_wall_faces() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scenarios/validation/dam_break_2d.toml"
        );
        let crate::load::Loaded {
            model: m,
            mut state,
        } = crate::load::load(path, &[]).unwrap();
        let st = &mut state;
        assert_eq!(Leakage::of(&m, st).deepest_dx, 0.0);
        let f: Vec<usize> = (0..st.len())
            .filter(|&i| m.phases[st.phase[i] as usize].kind != PhaseKind::Wall)
            .collect();
        let x_lo = m.to_local(m.domain_lo)[0] as f32;
        st.pos[f[0]][0] = x_lo - 0.3 * m.dx as f32;
        st.pos[f[1]][0] = x_lo - 0.7 * m.dx as f32;
        let l = Leakage::of(&m, st);
        assert!((l.deepest_dx - 0.7).abs() < 1e-3, "{l:?}");
        assert_eq!(l.particle, Some(st.id[f[1]]));
        assert_eq!(l.face, Some((0, 0)));
        assert_eq!(l.beyond_half_dx, 1);
        assert!(
            l.summary().contains("behind the x_min wall"),
            "{}",
            l.summary()
        );
    }
}

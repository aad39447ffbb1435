//! The consistency checks of a decoded model: the checksum of the file only guards against
//! corruption, not against a well-formed but inconsistent payload.

use super::Cascade;
use crate::error::RegressError;

impl Cascade {
    /// Recomputes what the model file does not store (the norms of the rounded samples),
    /// then checks consistency.
    pub(crate) fn finish_decode(&mut self) -> Result<(), RegressError> {
        for cl in &mut self.classes {
            cl.norms = cl.samples.norms();
        }
        if let Some(n) = &mut self.nystrom {
            n.norms = n.landmarks.norms();
        }
        self.check()?;
        self.check_nystrom()?;
        self.checked = true;
        Ok(())
    }

    /// Refuses a model deserialized by serde alone (see [`Cascade`]).
    pub(crate) fn check_decoded(&self) -> Result<(), RegressError> {
        if self.checked {
            Ok(())
        } else {
            Err(RegressError::Unchecked)
        }
    }

    /// The Nyström part: the classifier's landmarks in the model's storage (some exactly when
    /// there is a classifier), one finite weight per landmark and pair; the placements' own
    /// landmarks are checked as any model's samples ([`Self::check`]).
    fn check_nystrom(&self) -> Result<(), RegressError> {
        let Some(n) = &self.nystrom else {
            return Ok(());
        };
        let bad = |m: &str| Err(RegressError::Decode(format!("Nyström model: {m}")));
        n.landmarks.check()?;
        let m = n.landmarks.rows();
        let stored_dim = self
            .projection
            .as_ref()
            .map_or(self.dim, |p| p.stored_dim());
        if (m > 0) != self.classifier.is_some()
            || n.landmarks.is_projected() != self.projection.is_some()
            || n.landmarks.dim() != stored_dim
            || n.norms.len() != m
        {
            return bad("landmark sizes");
        }
        let np = self.classifier.as_ref().map_or(0, |h| h.pairs.len());
        if n.clf_weights.len() != m * np {
            return bad("weight sizes");
        }
        if self
            .classes
            .iter()
            .any(|cl| cl.samples.rows() == 0 || cl.n_classifier != 0)
        {
            return bad("placement sizes");
        }
        // The weights of its classifier; the rest is checked as any model's ([`Self::check`]).
        if !n.clf_weights.iter().all(|w| w.is_finite()) {
            return bad("non-finite weight or offset");
        }
        Ok(())
    }

    /// Consistency checks after decoding (the checksum only guards against corruption, not
    /// against a well-formed but inconsistent payload).
    fn check(&self) -> Result<(), RegressError> {
        let bad = |m: &str| Err(RegressError::Decode(m.to_string()));
        self.feature_config
            .validate()
            .map_err(|e| RegressError::Decode(format!("feature config: {e}")))?;
        if self.feature_config.feature_dim() != self.dim {
            return bad("feature config and model dimension disagree");
        }
        let k = self.placements.len();
        if k == 0 || self.classes.len() != k {
            return bad("placement count");
        }
        if !(self.regressor_gamma.is_finite() && self.regressor_gamma > 0.0) {
            return bad("regressor gamma");
        }
        let np = match &self.classifier {
            None if k == 1 => 0,
            None => return bad("missing classifier"),
            Some(h) => {
                if h.pairs.len() != k * (k - 1) / 2
                    || h.rho.len() != h.pairs.len()
                    || h.pairs
                        .iter()
                        .any(|&(a, b)| a as usize >= k || b as usize >= k)
                    || !(h.gamma.is_finite() && h.gamma > 0.0)
                {
                    return bad("classifier pairs");
                }
                h.pairs.len()
            }
        };
        let stored_dim = match &self.projection {
            None => self.dim,
            Some(p) => {
                p.check()?;
                if p.input_dim() != self.dim {
                    return bad("projection dimension");
                }
                p.stored_dim()
            }
        };
        for cl in &self.classes {
            cl.samples.check()?;
            let ns = cl.samples.rows();
            if cl.samples.is_projected() != self.projection.is_some()
                || cl.samples.dim() != stored_dim
                || cl.norms.len() != ns
                || cl.n_classifier > ns
                || cl.clf_coef.len() != cl.n_classifier * cl.clf_pairs.len()
                || cl.clf_pairs.windows(2).any(|w| w[0] >= w[1])
                || cl.clf_pairs.iter().any(|&p| p as usize >= np)
                || cl.reg_coef.len() != ns * cl.channels()
            {
                return bad("class sample store sizes");
            }
        }
        // Every number a query multiplies or adds: a non-finite one would give NaN velocities.
        let offsets = self.classes.iter().flat_map(|c| {
            c.reg_rho
                .iter()
                .copied()
                .chain(c.speed.as_ref().map(|s| s.rho))
        });
        let head = self.classifier.iter().flat_map(|h| h.rho.iter().copied());
        let coef = self
            .classes
            .iter()
            .flat_map(|c| c.reg_coef.iter().chain(&c.clf_coef).copied());
        if !coef.chain(offsets).chain(head).all(f64::is_finite) {
            return bad("non-finite weight or offset");
        }
        Ok(())
    }
}

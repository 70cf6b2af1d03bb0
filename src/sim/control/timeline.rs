//! A scene's timeline (TOML `[[timeline]]`): at given times attach a control target,
//! switch to another (morph), add one beside those attached (union), release one or all
//! (the shape collapses), or change their strength (a factor on c_cp). Events fire at the
//! start of the first frame whose scene time reaches them, in file order at equal times.
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Action {
    /// The first target, or one after everything was released.
    Attach,
    /// Release every attached target and attach this one.
    Switch,
    /// Attach this one beside those attached.
    Union,
    /// Release `target`, or every attached one.
    Release,
    /// Set the strength of `target`, or of every attached one.
    Strength,
}

impl Action {
    pub fn as_str(self) -> &'static str {
        match self {
            Action::Attach => "attach",
            Action::Switch => "switch",
            Action::Union => "union",
            Action::Release => "release",
            Action::Strength => "strength",
        }
    }
}

fn one() -> f32 {
    1.0
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Event {
    /// Scene time in seconds.
    pub time: f32,
    pub action: Action,
    /// A target's name (`[character]` is "character", `[[targets]]` by their `name`).
    #[serde(default)]
    pub target: Option<String>,
    /// Factor on the target's c_cp (attach, switch, union, strength).
    #[serde(default = "one")]
    pub strength: f32,
    /// Seconds over which a released target's pull fades to nothing (release, and the
    /// targets a switch lets go; default FADE). A held shape is compressed a little, and
    /// letting go at once turns that pressure into an explosion.
    #[serde(default)]
    pub fade: Option<f32>,
}

/// Default fade of a release (seconds).
pub const FADE: f32 = 0.2;

impl Event {
    pub fn new(time: f32, action: Action, target: Option<&str>) -> Self {
        Self {
            time,
            action,
            target: target.map(String::from),
            strength: 1.0,
            fade: None,
        }
    }

    pub fn fade(&self) -> f32 {
        self.fade.unwrap_or(FADE)
    }

    pub fn describe(&self) -> String {
        let who = self.target.as_deref().unwrap_or("every attached target");
        match self.action {
            Action::Release => format!("release {who} over {} s", self.fade()),
            Action::Strength => format!("strength {} for {who}", self.strength),
            a if self.strength != 1.0 => {
                format!("{} {who} at strength {}", a.as_str(), self.strength)
            }
            a => format!("{} {who}", a.as_str()),
        }
    }
}

/// What a fired event changes: (target index, attached, strength).
pub type Change = (usize, bool, f32);

/// The checked events in firing order and which have fired.
#[derive(Clone, Debug, Default)]
pub struct Timeline {
    events: Vec<Event>,
    next: usize,
    /// Per target: attached, strength (the state after the fired events).
    state: Vec<(bool, f32)>,
    names: Vec<String>,
}

impl Timeline {
    /// Check `events` against the targets `names` (those that can be controlled): times
    /// at least 0 and finite, named targets that exist, and every action valid in the
    /// state the earlier events leave (attach with nothing attached, union beside an
    /// attached target, release or strength of attached ones).
    pub fn new(scene: &str, events: &[Event], names: &[String]) -> Result<Self> {
        let bad = |i: usize, m: String| {
            Err(Error::Param(format!(
                "scene {scene}: timeline event {}: {m}",
                i + 1
            )))
        };
        let mut order: Vec<usize> = (0..events.len()).collect();
        for (i, e) in events.iter().enumerate() {
            if !(e.time.is_finite() && e.time >= 0.0) {
                return bad(i, format!("time must be at least 0, got {}", e.time));
            }
            if !(e.strength.is_finite() && e.strength >= 0.0) {
                return bad(
                    i,
                    format!("strength must be at least 0, got {}", e.strength),
                );
            }
            if !(e.fade().is_finite() && e.fade() >= 0.0) {
                return bad(i, format!("fade must be at least 0 s, got {}", e.fade()));
            }
            if let Some(t) = &e.target {
                if !names.contains(t) {
                    return bad(
                        i,
                        format!(
                            "no control target named '{t}' (targets: {})",
                            match names.is_empty() {
                                true => "none".into(),
                                false => names.join(", "),
                            }
                        ),
                    );
                }
            }
        }
        order.sort_by(|a, b| events[*a].time.total_cmp(&events[*b].time));
        let mut t = Self {
            events: order.iter().map(|i| events[*i].clone()).collect(),
            next: 0,
            state: vec![(false, 1.0); names.len()],
            names: names.to_vec(),
        };
        // Dry run: every event valid in the state its predecessors leave.
        let mut dry = t.clone();
        for (k, &i) in order.iter().enumerate() {
            if let Err(m) = dry.apply(k) {
                return bad(i, m);
            }
        }
        t.state = vec![(false, 1.0); names.len()];
        Ok(t)
    }

    /// Every target attached from the start at strength 1 (a scene without a timeline).
    pub fn all_attached(names: &[String]) -> Self {
        Self {
            events: Vec::new(),
            next: 0,
            state: vec![(true, 1.0); names.len()],
            names: names.to_vec(),
        }
    }

    pub fn attached(&self, target: usize) -> bool {
        self.state[target].0
    }

    pub fn strength(&self, target: usize) -> f32 {
        self.state[target].1
    }

    pub fn events(&self) -> &[Event] {
        &self.events
    }

    fn index(&self, name: &Option<String>) -> Option<usize> {
        name.as_ref()
            .and_then(|n| self.names.iter().position(|x| x == n))
    }

    /// Apply event `k` to the state; the changed targets, or why it cannot apply.
    fn apply(&mut self, k: usize) -> std::result::Result<Vec<Change>, String> {
        let e = self.events[k].clone();
        let target = self.index(&e.target);
        let attached: Vec<usize> = (0..self.state.len()).filter(|i| self.state[*i].0).collect();
        let mut changes = Vec::new();
        let need = |what: &str| format!("{what} needs a target");
        match e.action {
            Action::Attach | Action::Switch | Action::Union => {
                let t = target.ok_or_else(|| need(e.action.as_str()))?;
                if self.state[t].0 {
                    return Err(format!("'{}' is already attached", self.names[t]));
                }
                match e.action {
                    Action::Attach if !attached.is_empty() => {
                        return Err(format!(
                            "attach '{}' while '{}' is attached: use switch (morph) or union",
                            self.names[t], self.names[attached[0]]
                        ))
                    }
                    Action::Switch | Action::Union if attached.is_empty() => {
                        return Err(format!(
                            "{} '{}' with no target attached: use attach",
                            e.action.as_str(),
                            self.names[t]
                        ))
                    }
                    _ => {}
                }
                if e.action == Action::Switch {
                    for &a in &attached {
                        self.state[a].0 = false;
                        changes.push((a, false, self.state[a].1));
                    }
                }
                self.state[t] = (true, e.strength);
                changes.push((t, true, e.strength));
            }
            Action::Release | Action::Strength => {
                let which = match target {
                    Some(t) if !self.state[t].0 => {
                        return Err(format!(
                            "{} '{}', which is not attached",
                            e.action.as_str(),
                            self.names[t]
                        ))
                    }
                    Some(t) => vec![t],
                    None if attached.is_empty() => {
                        return Err(format!("{} with no target attached", e.action.as_str()))
                    }
                    None => attached,
                };
                for t in which {
                    match e.action {
                        Action::Release => self.state[t].0 = false,
                        _ => self.state[t].1 = e.strength,
                    }
                    changes.push((t, self.state[t].0, self.state[t].1));
                }
            }
        }
        Ok(changes)
    }

    /// Fire the events due by scene time `t`: each with its changes.
    pub fn due(&mut self, t: f64) -> Vec<(Event, Vec<Change>)> {
        let mut out = Vec::new();
        // A microsecond of slack: an event at a frame's time fires on that frame.
        while self.next < self.events.len() && self.events[self.next].time as f64 <= t + 1e-6 {
            let k = self.next;
            self.next += 1;
            let changes = self.apply(k).expect("checked by Timeline::new");
            out.push((self.events[k].clone(), changes));
        }
        out
    }
}

/// An event as it fired (`stats.control.events` of summary.json).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FiredEvent {
    pub frame: u64,
    /// Scene time of the frame it fired on.
    pub time: f64,
    pub event: Event,
}

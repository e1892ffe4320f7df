//! What comes in, on either transport, as rover's actions: the arm's task
//! (`/rover/arm/task`, std_msgs/String) and the controllers' commands, each topic polled in
//! turn. The transports decode their messages; what the words and values mean is here.

use rover_core::{Action, ArmMode, JointAction};

/// The arm's task topic.
pub(crate) const TASK_TOPIC: &str = "/rover/arm/task";

/// The action a task word asks for (`off`, `look`, `reach` or `pick`); anything else is a
/// warning and no action.
pub(crate) fn arm_task(word: &str) -> Option<Action> {
    match word.trim() {
        "off" => Some(Action::Arm(ArmMode::Off)),
        "look" => Some(Action::Arm(ArmMode::Look)),
        "reach" => Some(Action::Arm(ArmMode::Reach)),
        "pick" => Some(Action::Arm(ArmMode::Pick)),
        other => {
            tracing::warn!("{TASK_TOPIC}: \"{other}\" is not a task; expected off, look or reach");
            None
        }
    }
}

/// The first command among `topics`, each topic in turn from `*next` on (so that a busy one
/// does not starve the others); `*next` moves past the one that had it.
pub(crate) fn poll_in_turn<T>(
    topics: &mut [T],
    next: &mut usize,
    mut poll: impl FnMut(&mut T) -> Option<JointAction>,
) -> Option<Action> {
    let n = topics.len();
    for k in 0..n {
        let i = (*next + k) % n;
        if let Some(action) = poll(&mut topics[i]) {
            *next = (i + 1) % n;
            return Some(Action::Joint(action));
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn task_words_are_trimmed_and_others_refused() {
        assert_eq!(arm_task(" look\n"), Some(Action::Arm(ArmMode::Look)));
        assert_eq!(arm_task("reach"), Some(Action::Arm(ArmMode::Reach)));
        assert_eq!(arm_task("pick"), Some(Action::Arm(ArmMode::Pick)));
        assert_eq!(arm_task("grab"), None);
    }

    #[test]
    fn a_busy_topic_does_not_starve_the_others() {
        let command = |name: &str| JointAction::Controller {
            name: name.into(),
            value: 1.0,
        };
        let mut topics = ["a", "b"];
        let mut next = 0;
        let mut got = Vec::new();
        for _ in 0..4 {
            if let Some(Action::Joint(JointAction::Controller { name, .. })) =
                poll_in_turn(&mut topics, &mut next, |t| Some(command(t)))
            {
                got.push(name);
            }
        }
        assert_eq!(got, ["a", "b", "a", "b"]);
    }
}

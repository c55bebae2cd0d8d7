"""prompt(h) (eq. 3) and the retrievers that turn it into r (eq. 4).

prompt(h) = x_n                          if h = None   (watched to the end)
          = {I_0, x_s, I_s}              if h < ε      (stopped early)
          = {I_0, x_b, I_b, x_s, I_s}    otherwise

The ``vision`` retriever shows the images to a multimodal model p_ψ; the ``symbolic``
retriever describes the same moments from the trajectory log, for text-only models. In the
``structured`` variant it also names the skill being executed at the stop; in the ``faithful``
variant (:func:`faithful_prompt_h`, :func:`describe_view`, :func:`faithful_symbolic_retrieval`)
a stop carries only its time and what the pictures show — where the objects are and which block
the robot is holding — never which step of the plan was running.

Two numbers, as in the original code: ``epsilon`` (ε) is how long before the stop I_b is taken,
``early`` the stop time below which no I_b is shown (the paper's "h < ε" writes both as ε).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

from activeintent.learners import prompts
from activeintent.llm.base import ChatModel, ImagePart, Message, ModelError, TextPart
from activeintent.signals.stop import StopAnswer
from activeintent.world import WorldState, describe_skill, describe_state, relations
from activeintent.world.trajectory import Trajectory

RetrieverName = Literal["vision", "symbolic"]
RETRIEVERS: tuple[str, ...] = ("vision", "symbolic")


@dataclass
class Moment:
    """One of I_0, I_b, I_s: its caption x, time t and (for the vision path) the image."""

    label: str
    caption: str
    t: float


@dataclass
class PromptH:
    """prompt(h_i) of eq. 3 before rendering: the case and the moments to show."""

    case: Literal["none", "early", "late"]
    text: str  # x_n, or x_0 introducing the images
    moments: list[Moment] = field(default_factory=list)

    @property
    def image_labels(self) -> list[str]:
        return [m.label for m in self.moments]


def check_retriever(retriever: str, vlm: ChatModel) -> None:
    """The vision retriever reads images: refuse a model that accepts none, before any call."""
    if retriever == "vision" and not vlm.accepts_images:
        raise ModelError(
            f"The vision retriever needs a multimodal model, but {vlm.name} accepts no images; "
            "use --retriever symbolic or give a --vlm that accepts images."
        )


def prompt_h(traj: Trajectory, h: StopAnswer, goal: str, epsilon: float, early: float | None = None) -> PromptH:
    """Build prompt(h) as eq. 3 for the ``structured`` variant: I_b is ε seconds before the stop,
    shown when the stop came at ``early`` seconds or later (default: ε, the paper's h < ε).
    x_s names the skill being executed at the stop (see :func:`faithful_prompt_h` for the
    paper's prompt, which carries only the time and the images)."""
    early = epsilon if early is None else early
    x = prompts.sections("eq3_prompt_h")
    if h.stop_time is None:
        return PromptH("none", prompts.Template(x["x_n"]).substitute(goal=goal))
    step = traj.step_at(h.stop_time)
    skill = describe_skill(traj.steps[step].skill) if step is not None and traj.steps else "nothing yet"
    x0 = prompts.Template(x["x_0"]).substitute(goal=goal)
    xs = prompts.Template(x["x_s"]).substitute(stop_time=f"{h.stop_time:.1f}", skill=skill)
    i0 = Moment("I_0", "", 0.0)
    i_s = Moment("I_s", xs, h.stop_time)
    if h.stop_time < early:
        return PromptH("early", x0, [i0, i_s])
    xb = prompts.Template(x["x_b"]).substitute(epsilon=f"{epsilon:g}")
    return PromptH("late", x0, [i0, Moment("I_b", xb, max(0.0, h.stop_time - epsilon)), i_s])


def as_images(ph: PromptH, traj: Trajectory, size: tuple[int, int] = (240, 240)) -> list[TextPart | ImagePart]:
    """prompt(h) as message parts with rendered images I_0, I_b, I_s."""
    parts: list[TextPart | ImagePart] = [TextPart(text=ph.text)]
    for m in ph.moments:
        if m.caption:
            parts.append(TextPart(text=m.caption))
        parts.append(ImagePart.from_array(traj.frame(m.t, size=size)))
    return parts


def as_text(ph: PromptH, traj: Trajectory) -> str:
    """prompt(h) with each image replaced by a description of the scene at that moment."""
    lines = [ph.text]
    for m in ph.moments:
        if m.caption:
            lines.append(m.caption)
        lines.append(f"[{m.label}] {describe_state(traj.state_at(m.t))}")
    return "\n".join(lines)


def symbolic_retrieval(ph: PromptH, traj: Trajectory, h: StopAnswer) -> str:
    """r from the trajectory log: what changed between I_0/I_b and I_s, and the skill at the stop."""
    if h.stop_time is None:
        if not traj.moved_anything:  # nothing was shown: no stop is no approval
            return "The robot could not carry out the goal, so nothing moved; the user had nothing to judge."
        return f"The user watched the whole execution without stopping it. Final scene: {describe_state(traj.outcome)}"
    step = traj.step_at(h.stop_time)
    doing = describe_skill(traj.steps[step].skill) if step is not None and traj.steps else "nothing"
    first = relations(traj.state_at(ph.moments[0].t))
    last = relations(traj.state_at(h.stop_time))
    changes = []
    for name, rel in (("in", "inside"), ("on", "on"), ("next to", "next_to")):
        before = {tuple(p) for p in getattr(first, rel)}
        after = {tuple(p) for p in getattr(last, rel)}
        changes += [f"the {a} is now {name} the {b}" for a, b in sorted(after - before)]
        changes += [f"the {a} is no longer {name} the {b}" for a, b in sorted(before - after)]
    done = [describe_skill(s.skill) for s in traj.steps if s.end_tick <= traj.tick_at(h.stop_time)]
    text = f"The user stopped the robot while it was doing: {doing}."
    if done:
        text += f" Already completed before the stop: {'; '.join(done)}."
    if changes:
        text += f" Since the start, {'; '.join(changes)}."
    return text + f" The user objects to: {doing}."


def vision_messages(
    ph: PromptH, traj: Trajectory, history: str, size: tuple[int, int] = (240, 240)
) -> list[Message]:
    """The eq. 4 request for a multimodal model p_ψ: instructions, prompt(h) with images, earlier r."""
    head = prompts.render("eq4_retrieve", task=prompts.render("x_task"), prompt_h="The scene images follow.",
                          history=history or "none")
    return [Message(role="user", content=[TextPart(text=head), *as_images(ph, traj, size)])]


# -- the faithful variant: only the time of the stop and what the pictures show --------------------


def _held(state: WorldState, rel) -> list[str]:
    return [b for b in state.blocks if b not in rel.on_table and not rel.in_bowl(b) and not rel.below(b)]


def describe_view(state: WorldState) -> str:
    """What a picture of ``state`` shows, in words: where the objects are, and a block the robot
    is holding in the air (a block neither on the table, nor in a bowl, nor on another block)."""
    rel = relations(state)
    text = describe_state(state, rel)
    held = _held(state, rel)
    if held:
        text += " " + " ".join(f"The robot is holding the {b} in the air above the {rel.table_position[b]}." for b in held)
    return text


def faithful_prompt_h(traj: Trajectory, h: StopAnswer, goal: str, epsilon: float, early: float) -> PromptH:
    """prompt(h) of eq. 3 in the paper's terms: x_n when there was no stop (or nothing moved);
    {I_0, x_s, I_s} when the stop came before ``early`` seconds; else {I_0, x_b, I_b, x_s, I_s}
    with I_b taken ``epsilon`` seconds before the stop. x_s says only when the stop came."""
    x = prompts.sections("faithful_eq3")
    if h.stop_time is None:
        key = "x_n" if traj.moved_anything else "x_nothing"
        return PromptH("none", prompts.Template(x[key]).substitute(goal=goal))
    x0 = prompts.Template(x["x_0"]).substitute(goal=goal)
    i0 = Moment("I_0", "", 0.0)
    i_s = Moment("I_s", prompts.Template(x["x_s"]).substitute(stop_time=f"{h.stop_time:.1f}"), h.stop_time)
    if h.stop_time < early:
        return PromptH("early", x0, [i0, i_s])
    xb = prompts.Template(x["x_b"]).substitute(epsilon=f"{epsilon:g}")
    return PromptH("late", x0, [i0, Moment("I_b", xb, max(0.0, h.stop_time - epsilon)), i_s])


def as_view_text(ph: PromptH, traj: Trajectory) -> str:
    """prompt(h) for a text-only model: each picture replaced by :func:`describe_view`."""
    lines = [ph.text]
    for m in ph.moments:
        if m.caption:
            lines.append(m.caption)
        lines.append(f"[picture {m.label}] {describe_view(traj.state_at(m.t))}")
    return "\n".join(lines)


def _changes(before: WorldState, after: WorldState) -> list[str]:
    first, last = relations(before), relations(after)
    out = []
    for name, rel in (("in", "inside"), ("on", "on"), ("next to", "next_to")):
        was = {tuple(p) for p in getattr(first, rel)}
        now = {tuple(p) for p in getattr(last, rel)}
        out += [f"the {a} is now {name} the {b}" for a, b in sorted(now - was)]
        out += [f"the {a} is no longer {name} the {b}" for a, b in sorted(was - now)]
    held_before, held_now = _held(before, first), _held(after, last)
    out += [f"the robot has picked up the {b}" for b in held_now if b not in held_before]
    return out


def faithful_symbolic_retrieval(ph: PromptH, traj: Trajectory, h: StopAnswer) -> str:
    """r for text-only models, from the pictures of prompt(h) only (I_0, I_b, I_s): what
    changed between them and what the last one shows. No plan step, no skill name."""
    if h.stop_time is None:
        if not traj.moved_anything:
            return "The robot could not carry out the goal, so nothing moved; the person had nothing to judge."
        return f"The person watched the whole execution without stopping it. The table at the end: {describe_view(traj.outcome)}"
    at_stop = traj.state_at(h.stop_time)
    text = f"The person pressed stop at t = {h.stop_time:.1f} s."
    before = next((m for m in ph.moments if m.label == "I_b"), None)
    if before is not None:
        recent = _changes(traj.state_at(before.t), at_stop)
        text += (f" In the {h.stop_time - before.t:g} s before the stop: {'; '.join(recent)}." if recent
                 else f" Nothing visibly changed in the {h.stop_time - before.t:g} s before the stop.")
    since = _changes(traj.state_at(0.0), at_stop)
    if since:
        text += f" Since the start: {'; '.join(since)}."
    return text + f" The table at the stop: {describe_view(at_stop)}"

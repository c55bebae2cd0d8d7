"""The paper's three learners as the paper ran them (``--variant faithful``, the default).

What makes them faithful, against the ``structured`` variant in :mod:`activeintent.learners.paper.structured`:

- z and y are free text. Every answer starts with the model's own reasoning, then z, then y
  (one JSON object whose first field is ``reasoning``: grammar-constrained for the embedded
  base model, a JSON-schema response format for servers). y goes unchanged to the
  instruction-to-action module chosen with ``--executor`` (Code as Policies for every y with
  ``cap``; the parser-first short cut belongs to the structured variant).
- Multi-turn memory: p_θ keeps one conversation for the whole episode (the task x as the
  system turn, then every round's feedback, scene and its own answers), as the original code
  kept its message list; the MLLM's conversation carries the earlier rounds' images, and so
  does the retriever p_ψ's (eq. 4).
- A stop is only a time plus what the pictures show (:func:`retrievers.faithful_prompt_h`):
  no plan step or skill name reaches any prompt.
- Sampling at temperature 1 (p_θ; the original called the API at its default) with the
  trial's seed in every request, so trials are independent draws and a warm response cache
  still replays each of them exactly. The original asked its vision model at temperature 0,
  which ``retriever_temperature`` keeps.
- An answer that cannot be used (no valid JSON after the repair rounds) is recorded and the
  round goes on with the previous z and an empty y: K rounds run whatever the model says.
"""

from __future__ import annotations

import json
import time
from typing import Literal

from pydantic import BaseModel, ValidationError

from activeintent.learners import prompts
from activeintent.learners.base import Estimate, Learner, RoundRecord
from activeintent.learners.paper.retrievers import (
    PromptH,
    as_images,
    as_view_text,
    check_retriever,
    describe_view,
    faithful_prompt_h,
    faithful_symbolic_retrieval,
)
from activeintent.learners.paper.schemas import (
    FaithfulRetrieval,
    faithful_answer_schema,
    faithful_scene_schema,
)
from activeintent.learners.paper.structured import PaperLearnerConfig, failure_reason
from activeintent.llm.base import (
    ChatModel,
    ContextOverflowError,
    ImagePart,
    Message,
    ModelError,
    StructuredOutputError,
    TextPart,
)
from activeintent.signals.preference import PreferenceAnswer
from activeintent.signals.stop import StopAnswer
from activeintent.world import ALL_OBJECTS, Scene, SceneError, WorldState, layout
from activeintent.world.trajectory import Trajectory

Part = TextPart | ImagePart
SUMMARY_HEAD = ("Earlier rounds, in short (the whole conversation no longer fits your memory; "
                "what the person's answers said and what you answered):")
TEMPLATES = ("faithful_x", "faithful_scene", "faithful_eq12", "faithful_eq3", "faithful_eq4", "faithful_eq56",
             "faithful_final", "faithful_failed", "faithful_feedback")
# Not in TEMPLATES (whose hash versions every cached answer): a template added later leaves the
# recorded caches of the others usable; its own text is in the messages, which the key covers.
LATER_TEMPLATES = ("faithful_same_plans",)


class FaithfulConfig(PaperLearnerConfig):
    max_tokens: int = 700  # reasoning comes first, so answers are longer than the structured ones
    temperature: float = 1.0  # p_θ samples, as the original's API calls did (the default T = 1)
    retriever_temperature: float = 0.0  # p_ψ: the original asked its vision model at T = 0
    seed: int = 0  # the trial's seed, sent with every request (and so part of the cache key)


def _section(name: str, key: str, **values: object) -> str:
    return prompts.Template(prompts.sections(name)[key]).substitute({k: str(v) for k, v in values.items()})


def transcript_text(messages: list[Message]) -> str:
    """A conversation as text for the round record (images as <image>)."""
    out = []
    for m in messages:
        body = m.content if isinstance(m.content, str) else "\n".join(
            p.text if isinstance(p, TextPart) else "<image>" for p in m.content)
        out.append(f"[{m.role}]\n{body}")
    return "\n\n".join(out)


def user_turn(parts: list[Part]) -> Message:
    """One user message: plain text when there are no images (every backend takes that)."""
    if all(isinstance(p, TextPart) for p in parts):
        return Message(role="user", content="\n\n".join(p.text for p in parts if isinstance(p, TextPart)))
    return Message(role="user", content=list(parts))


def same_goal(a: str, b: str) -> bool:
    """Two goals that say the same, up to case, spacing and a final full stop."""
    def norm(text: str) -> str:
        return " ".join(text.casefold().split()).rstrip(".")
    return norm(a) == norm(b)


class _FaithfulLearner(Learner):
    """One conversation with p_θ per episode; subclasses say what feedback a round adds."""

    variant = "faithful"
    n_goals = 1
    round_template = "faithful_eq56"

    def __init__(self, llm: ChatModel, config: FaithfulConfig | None = None):
        self.llm = llm
        self.config = config or FaithfulConfig()
        self.history: list[RoundRecord] = []
        self.z = ""
        self.transcript: list[dict] = []
        system = _section("faithful_x", "x", objects=", ".join(ALL_OBJECTS)) + "\n" + _section("faithful_x", self.signal)
        self.conversation: list[Message] = [Message(role="system", content=system)]
        self.feedback: list[str] = []  # per exchange of the conversation: the feedback its user turn carried
        self.summarised: list[str] = []  # exchanges dropped from the conversation, one line each
        self.pending: list[Part] = []  # feedback not yet delivered: it opens the next user turn
        self._scoring = False  # between final() and the next round: failures belong to the test scene
        self._final: tuple[tuple[str, ...], list[Message]] | None = None  # last test-scene exchange
        self._final_note: str | None = None
        self._new_scene_asked = False

    # -- model calls -------------------------------------------------------------------------
    def _call(self, template: str, model: ChatModel, messages: list[Message], schema: type[BaseModel],
              temperature: float) -> BaseModel | None:
        """One structured call; None (recorded) when the answer stays unusable after repairs."""
        start = time.perf_counter()
        entry: dict = {"template": template, "model": model.name, "variant": self.variant,
                       "temperature": temperature, "seed": self.config.seed, "prompt": transcript_text(messages),
                       "images": sum(isinstance(p, ImagePart) for m in messages if not isinstance(m.content, str)
                                     for p in m.content)}
        try:
            answer = model.structured(messages, schema, temperature=temperature, max_tokens=self.config.max_tokens,
                                      prompt_version=prompts.version(*TEMPLATES), seed=self.config.seed)
        except StructuredOutputError as err:
            entry.update(unusable=str(err), s=round(time.perf_counter() - start, 4))
            self.transcript.append(entry)
            return None
        except ModelError as err:
            entry.update(error=str(err), s=round(time.perf_counter() - start, 4))
            self.transcript.append(entry)
            raise
        entry.update(answer=answer.model_dump(), s=round(time.perf_counter() - start, 4))
        self.transcript.append(entry)
        return answer

    def _converse(self, template: str, text: str, schema: type[BaseModel]) -> BaseModel | None:
        """Ask p_θ with the pending feedback and ``text`` as the next user turn; a usable answer
        joins the conversation (and the feedback is then delivered), else nothing changes."""
        while True:
            opening = [TextPart(text=_section("faithful_feedback", "first"))] if len(self.conversation) == 1 and not self.summarised else []
            turn = user_turn([*opening, *self.pending, TextPart(text=text)])
            try:
                answer = self._call(template, self.llm, [*self.conversation, turn], schema, self.config.temperature)
                break
            except ContextOverflowError:
                if not self._summarise_oldest():
                    raise
        if answer is not None:
            self.conversation += [turn, Message(role="assistant", content=answer.model_dump_json())]
            self.feedback.append("\n".join(p.text for p in self.pending if isinstance(p, TextPart)))
            self.pending = []
        return answer

    def _summarise_oldest(self) -> bool:
        """Keep the conversation within the model's context: the oldest exchange (a user turn
        and the answer to it) leaves the conversation and becomes one line of a summary in the
        system turn — the feedback it carried and the preference and goals answered, without
        the scene, the instructions and the model's reasoning. False when none is left."""
        if len(self.conversation) < 3:
            return False
        answer = self.conversation[2].text
        self.conversation = [self.conversation[0], *self.conversation[3:]]
        feedback = self.feedback.pop(0) if self.feedback else ""
        try:
            data = json.loads(answer)
        except ValueError:
            data = {}
        said = "; ".join(f"{k.replace('_', ' ')}: “{v}”" for k, v in data.items()
                         if k in ("preference", "goal", "goal_a", "goal_b") or (k in ("blocks", "bowls") and v))
        line = " ".join(x for x in (feedback.replace("\n", " "), f"You answered {said}." if said else "") if x)
        self.summarised.append(line or "(an exchange without feedback)")
        head = self.conversation[0].text.split(SUMMARY_HEAD)[0].rstrip()
        lines = "\n".join(f"{i + 1}. {x}" for i, x in enumerate(self.summarised))
        self.conversation[0] = Message(role="system", content=f"{head}\n\n{SUMMARY_HEAD}\n{lines}")
        if self._final is not None:
            self._final = None  # its exchange followed the old conversation
        return True

    def drain_transcript(self) -> list[dict]:
        out, self.transcript = self.transcript, []
        return out

    def stats(self) -> dict:
        return {"variant": self.variant, "turns": len(self.conversation), "summarised": len(self.summarised)}

    # -- the round ---------------------------------------------------------------------------
    def design_scene(self) -> Scene | None:
        self._scoring = False
        if not self.config.design_scenes:
            return None
        text = _section("faithful_scene", "ask")
        if self._new_scene_asked:
            text += "\n" + _section("faithful_scene", "new_scene")
        answer = self._converse("faithful_scene", text, faithful_scene_schema())
        if answer is None:
            return None
        self._new_scene_asked = False
        try:
            objects = [*answer.blocks, *answer.bowls]  # type: ignore[attr-defined]
            if len(objects) > 5:
                raise SceneError(f"a scene holds at most 5 objects, got {len(objects)}: {', '.join(objects)}")
            scene = Scene(objects=objects)
            layout(scene, 0)
        except (ValidationError, SceneError) as err:
            self.transcript.append({"template": "faithful_scene", "unusable": str(err).splitlines()[0]})
            return None
        return scene

    @staticmethod
    def _table(scene: Scene, state: WorldState) -> str:
        return f"Objects: {', '.join(scene.objects)}. {describe_view(state)}"

    def estimate(self, scene: Scene, state: WorldState) -> Estimate:
        self._scoring = False
        text = prompts.render(self.round_template, scene=self._table(scene, state))
        schema = faithful_answer_schema(self.n_goals, with_done=self.may_finish)
        answer = self._converse(self.round_template, text, schema)
        return self._estimate(answer)

    def _estimate(self, answer: BaseModel | None, n_goals: int | None = None, done: bool | None = None) -> Estimate:
        n = n_goals or self.n_goals
        if answer is None:  # the round goes on: the previous z, an empty y (nothing moves)
            return Estimate(z=self.z, goals=[""] * n, done=bool(done),
                            why={"variant": self.variant, "unusable": "no usable answer"})
        data = answer.model_dump()
        self.z = data["preference"]
        goals = [data["goal"]] if "goal" in data else [data["goal_a"], data["goal_b"]]
        return Estimate(z=self.z, goals=goals, done=bool(data.get("done", False) if done is None else done),
                        why={"variant": self.variant, "reasoning": data["reasoning"]})

    def execution_failed(self, goal: str, reason: str) -> None:
        note = prompts.render("faithful_failed", goal=goal, reason=failure_reason(reason))
        if self._scoring:
            self._final_note = note
        else:
            self.pending.append(TextPart(text=note))

    def final(self, scene: Scene, state: WorldState) -> Estimate:
        """y for a test scene: the conversation so far plus the test request, not kept."""
        self._scoring = True
        key = tuple(scene.objects)
        schema = faithful_answer_schema(1)
        if self._final_note and self._final and self._final[0] == key:
            messages = [*self.conversation, *self._final[1], Message(role="user", content=self._final_note)]
        else:
            text = prompts.render("faithful_final", scene=self._table(scene, state))
            messages = [*self.conversation, user_turn([*self.pending, TextPart(text=text)])]
        self._final_note = None
        while True:
            try:
                answer = self._call("faithful_final", self.llm, messages, schema, self.config.temperature)
                break
            except ContextOverflowError:
                if not self._summarise_oldest():
                    raise
                messages = [*self.conversation, messages[-1]]  # the test request stays as it was
        if answer is not None:
            self._final = (key, [messages[-1], Message(role="assistant", content=answer.model_dump_json())])
        return self._estimate(answer, 1, True)

    def observe(self, record: RoundRecord, trajectories: list[Trajectory]) -> str | None:
        self._scoring = False
        self.history.append(record)
        h = record.answer
        if h is not None and h.new_scene:
            self._new_scene_asked = True
            self.pending.append(TextPart(text=_section("faithful_feedback", "new_scene", goal=" / ".join(record.estimate.goals))))
            return None
        return self._feedback(record, trajectories)

    def _feedback(self, record: RoundRecord, trajectories: list[Trajectory]) -> str | None:
        raise NotImplementedError


class FaithfulPreferenceLearner(_FaithfulLearner):
    """Eq. 1–2: z_{i+1} then {y^a, y^b} from p_θ, conditioned on every earlier z, y, h (the
    conversation); h ∈ {A, B, cannot choose}."""

    name = "preference"
    signal = "preference"
    may_finish = True
    n_goals = 2
    round_template = "faithful_eq12"

    max_reasks = 2  # asks again at most this often when goals A and B are the same
    alike_reasks = 0  # rounds asked again because A and B became one motion

    def stats(self) -> dict:
        return {**super().stats(), "alike_reasks": self.alike_reasks}

    def estimate(self, scene: Scene, state: WorldState) -> Estimate:
        """Eq. 1–2, asked again (in the same conversation) while A and B are one goal: two
        identical showcases cannot be told apart, so the answer would carry nothing."""
        self._scoring = False
        text = prompts.render(self.round_template, scene=self._table(scene, state))
        schema = faithful_answer_schema(self.n_goals, with_done=self.may_finish)
        answer = self._converse(self.round_template, text, schema)
        reasked = 0
        while answer is not None and same_goal(answer.goal_a, answer.goal_b) and reasked < self.max_reasks:  # type: ignore[attr-defined]
            reasked += 1
            again = _section("faithful_feedback", "same_goals", a=answer.goal_a)  # type: ignore[attr-defined]
            newer = self._converse(self.round_template, again, schema)
            if newer is None:
                break  # unusable: the answer we have stands
            answer = newer
        estimate = self._estimate(answer)
        if reasked:
            estimate.why["reasked_same_goals"] = reasked
        return estimate

    def showcases_alike(self, goals: list[str]) -> bool:
        a, b = (goals + ["", ""])[:2]
        self.pending.append(TextPart(text=prompts.render("faithful_same_plans", a=a, b=b)))
        self.alike_reasks += 1
        return True

    def _feedback(self, record: RoundRecord, trajectories: list[Trajectory]) -> str | None:
        h = record.answer
        assert isinstance(h, PreferenceAnswer)
        a, b = (record.estimate.goals + ["", ""])[:2]
        self.pending.append(TextPart(text=_section("faithful_feedback", f"choice_{h.choice}" if h.choice in ("A", "B") else "cant_choose", a=a, b=b)))
        for label, traj, failure in zip("AB", trajectories, record.failures + [None, None], strict=False):
            if not traj.moved_anything:
                self.pending.append(TextPart(text=_section("faithful_feedback", "failed", label=label,
                                                           reason=failure_reason(failure or "nothing could be done"))))
        return None


class _FaithfulStopLearner(_FaithfulLearner):
    signal = "stop"

    def _outcome(self, record: RoundRecord, traj: Trajectory) -> tuple[str, PromptH]:
        h = record.answer
        assert isinstance(h, StopAnswer)
        goal = record.estimate.goals[0] if record.estimate.goals else ""
        ph = faithful_prompt_h(traj, h, goal, self.config.epsilon, self._early())
        if h.stop_time is not None:
            key, values = "stopped", {"stop_time": f"{h.stop_time:.1f}", "goal": goal}
        else:
            key, values = ("watched" if traj.moved_anything else "nothing"), {"goal": goal}
        return _section("faithful_feedback", key, **values), ph

    def _early(self) -> float:
        return self.config.epsilon if self.config.early_threshold is None else self.config.early_threshold


class FaithfulMllmLlmLearner(_FaithfulStopLearner):
    """Eq. 3–6: p_ψ turns prompt(h_i) and y_i into r_i, in its own conversation with every
    earlier prompt(h), y and r (images included); p_θ then gives z_{i+1}, y_{i+1} from r_i, h_i,
    y_i and its conversation. ``symbolic``: r from the pictures' contents, no model."""

    name = "mllm-llm"

    def __init__(self, llm: ChatModel, vlm: ChatModel | None = None,
                 retriever: Literal["vision", "symbolic"] = "symbolic", config: FaithfulConfig | None = None):
        super().__init__(llm, config)
        self.vlm = vlm or llm
        check_retriever(retriever, self.vlm)
        self.retriever = retriever
        self.vision: list[Message] = [Message(role="system", content=_section("faithful_eq4", "system"))]

    def _feedback(self, record: RoundRecord, trajectories: list[Trajectory]) -> str | None:
        if not trajectories:
            return None
        text, ph = self._outcome(record, trajectories[0])
        r = self._retrieve(ph, trajectories[0], record.answer)  # type: ignore[arg-type]
        self.pending.append(TextPart(text=text))
        if r:
            self.pending.append(TextPart(text=_section("faithful_feedback", "retrieved", r=r)))
        return r

    def _retrieve(self, ph: PromptH, traj: Trajectory, h: StopAnswer) -> str | None:
        if self.retriever == "symbolic" or (h.stop_time is None and not traj.moved_anything):
            return faithful_symbolic_retrieval(ph, traj, h)
        size = (self.config.image_size, self.config.image_size)
        parts: list[Part] = as_images(ph, traj, size) if ph.moments else [TextPart(text=ph.text)]
        parts.append(TextPart(text=_section("faithful_eq4", "stopped" if h.stop_time is not None else "watched")))
        turn = user_turn(parts)
        answer = self._call("faithful_eq4", self.vlm, [*self.vision, turn], FaithfulRetrieval,
                            self.config.retriever_temperature)
        if answer is None:
            return None
        self.vision += [turn, Message(role="assistant", content=answer.model_dump_json())]
        return answer.retrieved  # type: ignore[attr-defined]


class FaithfulMllmLearner(_FaithfulStopLearner):
    """One multimodal model does all: prompt(h_i) (eq. 3) with its images joins its own
    conversation, and it gives z_{i+1}, y_{i+1}. A text-only model gets the pictures described."""

    name = "mllm"

    def __init__(self, llm: ChatModel, config: FaithfulConfig | None = None):
        super().__init__(llm, config)
        self.retriever = "vision" if llm.accepts_images else "symbolic"
        self.sees_images = llm.accepts_images

    def _feedback(self, record: RoundRecord, trajectories: list[Trajectory]) -> str | None:
        if not trajectories:
            return None
        traj = trajectories[0]
        text, ph = self._outcome(record, traj)
        self.pending.append(TextPart(text=text))
        # Pictures when the model sees images and the env draws them (--env symbolic cannot):
        # else the pictures described; ``retriever`` records which, round by round.
        self.retriever = "vision" if self.sees_images and traj.renderer is not None else "symbolic"
        if ph.moments:  # a stop: show what the person saw
            self.pending.append(TextPart(text=_section("faithful_feedback", "evidence")))
            if self.retriever == "vision":
                size = (self.config.image_size, self.config.image_size)
                self.pending += as_images(ph, traj, size)
            else:
                self.pending.append(TextPart(text=as_view_text(ph, traj)))
        return None

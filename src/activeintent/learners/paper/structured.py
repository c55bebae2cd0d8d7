"""The paper's three learners, ``--variant structured``: `preference` (eq. 1–2), `mllm-llm`
(eq. 3–6), `mllm`. The paper's own way of running them (free text, reasoning, multi-turn
memory, sampling) is ``--variant faithful``, the default, in :mod:`activeintent.learners.paper.faithful`.

Each round the model p_θ estimates the intention z_{i+1} from the history, then the
instruction(s) y_{i+1} given z_{i+1}; stop-signal methods first turn the user's stop h_i into
text r_i with a retriever (eq. 3–4). All answers are structured (pydantic), never parsed line
by line.
"""

from __future__ import annotations

import re
import time
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from activeintent.learners import prompts
from activeintent.learners.base import Estimate, Learner, RoundRecord
from activeintent.learners.paper.retrievers import (
    PromptH,
    as_images,
    as_text,
    check_retriever,
    prompt_h,
    symbolic_retrieval,
    vision_messages,
)
from activeintent.learners.paper.schemas import (
    IntentionAnswer,
    RetrievalAnswer,
    goals_schema,
    scene_schema,
)
from activeintent.llm.base import ChatModel, ImagePart, Message, ModelError, TextPart
from activeintent.signals.stop import StopAnswer
from activeintent.world import ALL_OBJECTS, Scene, SceneError, WorldState, describe_state, layout
from activeintent.world.trajectory import Trajectory


def failure_reason(text: str | None) -> str:
    """The reason alone from an executor's feedback text ("I failed to generate the goal; please
    generate a simpler goal … Reason (stage): why"): learners phrase the request for a simpler
    goal themselves, so it is not said twice."""
    text = (text or "").strip()
    if m := re.search(r"Reason \((\w+)\): (.*)$", text, re.DOTALL):
        return f"{m[1]} failed: {m[2].strip()}"
    return text or "no reason given"


VARIANTS = ("faithful", "structured")


class PaperSettings(BaseModel):
    """What a person running the paper's methods chooses."""

    model_config = ConfigDict(extra="forbid")

    variant: str = Field("faithful", description="faithful (as the paper ran them: free text, reasoning, memory, "
                         "T = 1) | structured")
    retriever: str = Field("symbolic", pattern="^(symbolic|vision)$", description="r from a stop: symbolic | vision")
    design_scenes: bool = Field(True, description="Let the learner choose each round's objects")
    epsilon: float = Field(2.0, ge=0, description="ε: seconds before the stop for image I_b (eq. 3)")
    early_threshold: float | None = Field(2.0, ge=0, description="eq. 3's \"h < ε\": a stop earlier than this (s) "
                                          "shows no I_b (None: ε)")

    @field_validator("variant")
    @classmethod
    def _known_variant(cls, v: str) -> str:
        if v not in VARIANTS:
            raise ValueError(f"Unknown variant {v!r}; valid variants: {', '.join(VARIANTS)}.")
        return v


class PaperLearnerConfig(PaperSettings):
    image_size: int = 240
    max_tokens: int = 256


class _ModelLearner(Learner):
    """Shared plumbing: model calls with a transcript, history text, scene design."""

    variant = "structured"
    executor_parses_first = True

    def __init__(self, llm: ChatModel, config: PaperLearnerConfig | None = None):
        self.llm = llm
        self.config = config or PaperLearnerConfig()
        self.history: list[RoundRecord] = []
        self.retrieved: list[str | None] = []
        self.notes: list[str] = []  # executor failures told to the model, as the original did
        self.transcript: list[dict] = []
        self.task = prompts.render("x_task")

    # -- model calls -------------------------------------------------------------------------
    def _ask(self, template: str, model: ChatModel, messages: list[Message], schema: type[BaseModel]):
        start = time.perf_counter()
        entry: dict = {"template": template, "model": model.name, "prompt": _message_text(messages),
                       "images": sum(isinstance(p, ImagePart) for m in messages if not isinstance(m.content, str) for p in m.content)}
        try:
            answer = model.structured(messages, schema, max_tokens=self.config.max_tokens,
                                      prompt_version=prompts.version(template))
        except ModelError as err:
            entry.update(error=str(err), s=time.perf_counter() - start)
            self.transcript.append(entry)
            raise
        entry.update(answer=answer.model_dump(), s=round(time.perf_counter() - start, 4))
        self.transcript.append(entry)
        return answer

    def drain_transcript(self) -> list[dict]:
        out, self.transcript = self.transcript, []
        return out

    def stats(self) -> dict:
        return {"variant": self.variant}

    def execution_failed(self, goal: str, reason: str) -> None:
        self.notes.append(f'I failed to generate the goal "{goal}" ({failure_reason(reason)}); please generate '
                          "a simpler goal similar to the previous one.")

    # -- scene design ------------------------------------------------------------------------
    def design_scene(self) -> Scene | None:
        if not self.config.design_scenes:
            return None
        text = prompts.render("x_scene_design", task=self.task, history=self.history_text() or "nothing yet",
                              objects=", ".join(ALL_OBJECTS))
        try:
            choice = self._ask("x_scene_design", self.llm, [Message(role="user", content=text)], scene_schema())
            scene = Scene(objects=choice.objects)
            if len(scene.blocks) < 2 or not scene.bowls:
                raise SceneError(f"a scene needs at least 2 blocks and a bowl, got {scene}")
            layout(scene, 0)
        except (ModelError, ValidationError, SceneError) as err:
            self.transcript.append({"template": "x_scene_design", "unusable": str(err).splitlines()[0]})
            return None
        return scene

    # -- prompts -----------------------------------------------------------------------------
    def history_text(self) -> str:
        lines = []
        for rec, r in zip(self.history, self.retrieved, strict=False):
            lines.append(self._round_text(rec, r))
        lines += self.notes
        return "\n".join(lines)

    def _round_text(self, rec: RoundRecord, r: str | None) -> str:
        raise NotImplementedError

    def _scene_values(self, scene: Scene, state: WorldState) -> dict[str, str]:
        return {"scene_description": describe_state(state), "objects": ", ".join(scene.objects)}

    def _goals(self, scene: Scene, state: WorldState, z: str, n: int, extra: list[TextPart | ImagePart] | None = None) -> list[str]:
        history = self.history_text() or "none yet"
        if n == 1:
            text = prompts.render("eq6_instruction", task=self.task, history=history, preference=z,
                                  **self._scene_values(scene, state))
            template = "eq6_instruction"
        else:
            request = ("Write two different goals, A and B, for this scene. Both should agree with the "
                       "preference z as far as it is known, but differ in a way that the user's choice "
                       "between them will tell us more about the preference.")
            text = prompts.render("eq2_instructions", task=self.task, history=history, preference=z,
                                  request=request, **self._scene_values(scene, state))
            template = "eq2_instructions"
        content: str | list = text if not extra else [TextPart(text=text), *extra]
        answer = self._ask(template, self.llm, [Message(role="user", content=content)], goals_schema(scene, n))
        return [answer.goal] if n == 1 else [answer.goal_a, answer.goal_b]


def _message_text(messages: list[Message]) -> str:
    out = []
    for m in messages:
        if isinstance(m.content, str):
            out.append(m.content)
        else:
            out.append("\n".join(p.text if isinstance(p, TextPart) else "<image>" for p in m.content))
    return "\n\n".join(out)


class PreferenceLearner(_ModelLearner):
    """Preference signal (eq. 1–2): z_{i+1} ~ p_θ(z | z_i, y_i, h_i, …, x), then
    y_{i+1} = {y^a, y^b} ~ p_θ(y | z_{i+1}, z_i, y_i, h_i, …, x); h ∈ {A, B, can't choose}."""

    name = "preference"
    signal = "preference"
    may_finish = True  # in the paper only the preference method could answer "done"

    def _round_text(self, rec: RoundRecord, r: str | None) -> str:
        h = rec.answer.describe() if rec.answer else "no answer"
        a, b = (rec.estimate.goals + ["", ""])[:2]
        return (f"Round {rec.index + 1}: scene: {rec.scene}. z_{rec.index + 1}: {rec.estimate.z} "
                f"Goal A: {a}. Goal B: {b}. h_{rec.index + 1}: {h}.")

    def _intention(self) -> IntentionAnswer:
        text = prompts.render("eq1_intention", task=self.task, history=self.history_text() or "none yet")
        return self._ask("eq1_intention", self.llm, [Message(role="user", content=text)], IntentionAnswer)

    def estimate(self, scene: Scene, state: WorldState) -> Estimate:
        z = self._intention()
        return Estimate(z=z.preference, goals=self._goals(scene, state, z.preference, 2), done=z.done)

    def observe(self, record: RoundRecord, trajectories: list[Trajectory]) -> str | None:
        self.history.append(record)
        self.retrieved.append(None)
        self.notes.clear()
        return None

    def final(self, scene: Scene, state: WorldState) -> Estimate:
        z = self._intention()
        return Estimate(z=z.preference, goals=self._goals(scene, state, z.preference, 1), done=True)


class _StopLearner(_ModelLearner):
    signal = "stop"

    def _round_text(self, rec: RoundRecord, r: str | None) -> str:
        h = rec.answer.describe() if rec.answer else "no answer"
        text = (f"Round {rec.index + 1}: scene: {rec.scene}. z_{rec.index + 1}: {rec.estimate.z} "
                f"y_{rec.index + 1}: {rec.estimate.goals[0]}. h_{rec.index + 1}: {h}.")
        return text + (f" r_{rec.index + 1}: {r}" if r else "")

    def _intention(self, extra: list[TextPart | ImagePart] | None = None) -> IntentionAnswer:
        text = prompts.render("eq5_intention", task=self.task, history=self.history_text() or "none yet")
        content: str | list = text if not extra else [TextPart(text=text), *extra]
        return self._ask("eq5_intention", self.llm, [Message(role="user", content=content)], IntentionAnswer)

    def estimate(self, scene: Scene, state: WorldState) -> Estimate:
        extra = self._latest_evidence()
        z = self._intention(extra)
        return Estimate(z=z.preference, goals=self._goals(scene, state, z.preference, 1, extra), done=z.done)

    def final(self, scene: Scene, state: WorldState) -> Estimate:
        z = self._intention(self._latest_evidence())
        return Estimate(z=z.preference, goals=self._goals(scene, state, z.preference, 1), done=True)

    def _latest_evidence(self) -> list[TextPart | ImagePart] | None:
        return None


class MllmLlmLearner(_StopLearner):
    """Stop signal with a retriever (eq. 3–6): r_i ~ p_ψ(r | prompt(h_i), y_i, r_{i-1}, …);
    z_{i+1} ~ p_θ(z | r_i, h_i, y_i, …); y_{i+1} ~ p_θ(y | z_{i+1}, r_i, h_i, y_i, …)."""

    name = "mllm-llm"

    def __init__(self, llm: ChatModel, vlm: ChatModel | None = None,
                 retriever: Literal["vision", "symbolic"] = "symbolic", config: PaperLearnerConfig | None = None):
        super().__init__(llm, config)
        self.vlm = vlm or llm
        check_retriever(retriever, self.vlm)
        self.retriever = retriever

    def observe(self, record: RoundRecord, trajectories: list[Trajectory]) -> str | None:
        h = record.answer
        assert isinstance(h, StopAnswer)
        r = None
        if trajectories and not h.new_scene:
            traj, goal = trajectories[0], record.estimate.goals[0]
            ph = prompt_h(traj, h, goal, self.config.epsilon, self.config.early_threshold)
            if self.retriever == "vision":
                past = "\n".join(f"y: {rec.estimate.goals[0]}; r: {rr}" for rec, rr in zip(self.history, self.retrieved, strict=False) if rr)
                size = (self.config.image_size, self.config.image_size)
                r = self._ask("eq4_retrieve", self.vlm, vision_messages(ph, traj, past, size), RetrievalAnswer).retrieved
            else:
                r = symbolic_retrieval(ph, traj, h)
        self.history.append(record)
        self.retrieved.append(r)
        self.notes.clear()
        return r


class MllmLearner(_StopLearner):
    """Stop signal, one multimodal model does all: it sees prompt(h_i) (eq. 3) itself and
    produces z_{i+1} and y_{i+1}. A text-only model sees the scenes described instead."""

    name = "mllm"

    def __init__(self, llm: ChatModel, config: PaperLearnerConfig | None = None):
        super().__init__(llm, config)
        self.retriever = "vision" if llm.accepts_images else "symbolic"
        self._evidence: tuple[PromptH, Trajectory] | None = None

    def observe(self, record: RoundRecord, trajectories: list[Trajectory]) -> str | None:
        h = record.answer
        assert isinstance(h, StopAnswer)
        self._evidence = None
        if trajectories and not h.new_scene:
            ph = prompt_h(trajectories[0], h, record.estimate.goals[0], self.config.epsilon, self.config.early_threshold)
            self._evidence = (ph, trajectories[0])
        self.history.append(record)
        self.retrieved.append(None)
        self.notes.clear()
        return None

    def _latest_evidence(self) -> list[TextPart | ImagePart] | None:
        if self._evidence is None:
            return None
        ph, traj = self._evidence
        head = TextPart(text="What the user saw in the last round (prompt(h)):")
        if self.retriever == "vision":
            size = (self.config.image_size, self.config.image_size)
            return [head, *as_images(ph, traj, size)]
        return [head, TextPart(text=as_text(ph, traj))]

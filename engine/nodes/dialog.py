"""Reply: answer what was heard from a dialog file."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any, ClassVar

from py_trees.common import Status

from engine.dialogs.confirming import (
    IN_PARTS_WITHIN_S,
    IN_PARTS_WORDS,
    REPROMPT_WITHIN_S,
    maybe_meant,
    reprompt,
)
from engine.dialogs.model import Dialog, FollowUp, Match, Verdict
from engine.errors import ServiceError
from engine.nodes.base import Leaf
from engine.services.actions import SPOKEN_OVER
from engine.services.jobs import ImmediateJob, Job
from engine.services.turns import SPEAKER
from engine.session.events import NotUnderstood
from engine.values.param_problems import CheckContext, ParamIssue, did_you_mean
from engine.values.params import Key, Param, Text
from engine.values.templates import CompiledTemplate


class Reply(Leaf):
    """Answer an utterance with the best-matching rule of a dialog (dialogs/NAME.yaml).

    When the rule says ``read: temperature`` (or ultrasound), the sensor is read first and
    the answer is filled with the new value; ``{fields}`` of other keys are filled with
    their current value. When the rule's answer asked a question (``then:``), the next
    utterance within its ``listen_s`` is matched against the follow-up's rules first.
    RUNNING while reading and speaking; SUCCESS when the answer was said; FAILURE when no
    rule matched and the dialog has no fallback, a field has no value yet, or a sensor or
    the speech service failed.

    A child who pauses mid-sentence is heard in two parts ("do you like" ... "dogs"): an
    utterance not understood alone, heard within a few seconds of one not understood, is
    judged joined to it, and answered so when that matches a rule.

    When nothing matches but what was heard is like a rule that says how to confirm it,
    the robot asks (``confirm:``) and a yes is answered as that rule; when it does not
    understand again soon after a sorry, it says the dialog's next ``reprompt:`` instead
    (:mod:`engine.dialogs.confirming`).
    """

    uses = (SPEAKER,)

    params: ClassVar = (
        Param("heard", Key(), doc="the /vars/ key holding the utterance"),
        Param("dialog", Text(), "default", "which dialog (file in dialogs/, without .yaml)"),
    )

    @classmethod
    def check_params(cls, args: Mapping[str, Any], ctx: CheckContext) -> list[ParamIssue]:
        dialog = args.get("dialog")
        if ctx.dialogs is not None and dialog is not None and ctx.dialogs.get(dialog) is None:
            known = ctx.dialogs.names
            hint = did_you_mean(dialog, known) or (
                "dialogs: " + ", ".join(known) if known else "add dialogs/NAME.yaml"
            )
            return [ParamIssue("dialog", f"no dialog named {dialog!r}", hint)]
        return []

    def __init__(self, *a: Any) -> None:
        super().__init__(*a)
        self.job: Job | None = None
        self.answer: CompiledTemplate | None = None
        self.phase = "idle"
        self.follow_up: FollowUp | None = None
        self.follow_up_until_s = 0.0
        self.misses = 0
        """Utterances not understood in a row, each within REPROMPT_WITHIN_S of the last."""
        self.missed_at_s = -REPROMPT_WITHIN_S
        self.unmatched = ""
        """The words of the utterance not understood just before (joined to the next)."""
        self.unmatched_asked: FollowUp | None = None
        """The rule's question that utterance answered (a follow-up), if any."""

    def dialog(self) -> Dialog:
        dialogs = self.ctx.dialogs
        dialog = dialogs.get(self.args.dialog) if dialogs is not None else None
        if dialog is None:
            raise LookupError(f"dialog {self.args.dialog!r} is not loaded")
        return dialog

    def initialise(self) -> None:
        self.job, self.answer, self.phase = None, None, "idle"
        heard = self.read(self.args.heard)
        dialog = self.dialog()
        asked = self.follow_up if self.ctx.clock.now() <= self.follow_up_until_s else None
        self.follow_up, self.follow_up_until_s = None, 0.0
        verdict = dialog.judge(str(heard), asked) if heard else None
        match = verdict.match if verdict is not None else None
        parts = ""
        if match is None and heard and self._ends_a_sentence():
            match = self._in_parts(dialog, str(heard), asked)
            joined = f"{self.unmatched} {heard}"
            parts = f", heard in parts: {joined!r}" if match is not None else ""
        if match is None:
            if heard:  # perhaps the start of a sentence the next utterance ends
                self.unmatched = " ".join(str(heard).split()[-IN_PARTS_WORDS:])
                # a rule's question stays open for the rest; a yes or no to whether it
                # heard right is said at once, or the question has passed
                self.unmatched_asked = asked if asked is not None and not asked.confirms else None
            self._not_understood(dialog, str(heard or ""), verdict, asked)
            return
        self.misses, self.unmatched = 0, ""
        self.feedback_message = (
            f"rule {match.rule.id!r} at line {match.rule.line} ({match.score:.2f}){parts}"
        )
        self.answer = match.rule.answer
        if match.rule.follow_up is not None:
            self.follow_up = match.rule.follow_up
        if match.rule.read:
            self.phase = "reading"
            self.job = self.ctx.actions.read_sensor(match.rule.read)
        else:
            self._speak(self.answer)

    def _ends_a_sentence(self) -> bool:
        """Whether what was heard now may end the sentence the utterance before began: that
        one was not understood either, a moment ago."""
        return bool(self.unmatched) and self.ctx.clock.now() - self.missed_at_s <= IN_PARTS_WITHIN_S

    def _in_parts(self, dialog: Dialog, heard: str, asked: FollowUp | None) -> Match | None:
        """The rule the two parts match as one sentence (judged with the question the first
        part answered). Where ``heard`` alone is like a rule the robot would ask about,
        only that rule: an unrelated start does not turn its question into another answer."""
        both = dialog.judge(f"{self.unmatched} {heard}", self.unmatched_asked or asked).match
        maybe = maybe_meant(dialog, heard, asked)
        if both is None or (maybe is not None and maybe.confirm and both.rule.id != maybe.id):
            return None
        return both

    def _not_understood(
        self, dialog: Dialog, heard: str, verdict: Verdict | None, asked: FollowUp | None
    ) -> None:
        """Ask whether it heard a rule it is like, else say sorry (in other words when it
        said sorry a moment ago): :mod:`engine.dialogs.confirming`."""
        why = verdict.reason if verdict is not None else "nothing was heard"
        self.feedback_message = f"no rule matches {heard!r}: {why}"
        if not heard:
            return
        now = self.ctx.clock.now()
        maybe = maybe_meant(dialog, heard, asked)
        again = now - self.missed_at_s <= REPROMPT_WITHIN_S
        self.misses, self.missed_at_s = (self.misses + 1 if again else 1), now
        said: CompiledTemplate | None
        if maybe is not None and maybe.confirm is not None:
            self.feedback_message += f"; asks whether it heard rule {maybe.id!r}"
            self.follow_up, said, reprompted = maybe.confirmed, maybe.confirm, 0
        elif asked is not None and asked.otherwise is not None:
            said, reprompted = asked.otherwise, 0
        else:
            said, reprompted = reprompt(dialog, self.misses)
        if self.ctx.session is not None:
            asked_about = maybe.id if maybe is not None else ""
            self.ctx.session.publish(
                NotUnderstood(now, self.ctx.tree, heard, why, asked_about, reprompted)
            )
        if said is not None:
            self._speak(said)

    def _speak(self, template: CompiledTemplate, read: Callable[[str], Any] | None = None) -> None:
        self.phase = "speaking"
        try:
            text = template.fill(read or self.read)
        except (KeyError, ValueError) as error:  # a field with no value, or a bad value
            self.job = ImmediateJob(error=ServiceError(str(error).strip("'\"")))
            return
        # the answer is the robot's own words, with what its fields fill in (a reading,
        # or what was heard when the dialog echoes it): not the utterance that chose it
        self.job = self.ctx.actions.say(text, carries=self.ctx.blackboard.carried_by(template.keys))

    def terminate(self, new_status: Status) -> None:
        """Halted while asking its question because the person spoke over it once the
        question had begun (its answer's last sentence): their words are the answer, so the
        follow-up listens from now, as after a question said whole. Over what came before
        the question, the person never heard it: their words are new."""
        super().terminate(new_status)
        actions, asked = self.ctx.actions, self.follow_up
        spoken_over = actions.stop_reason == SPOKEN_OVER and actions.last_sentence_heard
        if new_status == Status.INVALID and spoken_over and self.phase == "speaking" and asked:
            self.follow_up_until_s = self.ctx.clock.now() + asked.listen_s

    def update(self) -> Status:
        if self.job is None:
            return Status.FAILURE
        status = self.job_status(self.job, failed="could not answer")
        if status == Status.SUCCESS and self.phase == "speaking" and self.follow_up is not None:
            self.follow_up_until_s = self.ctx.clock.now() + self.follow_up.listen_s
        if status == Status.SUCCESS and self.phase == "reading" and self.answer is not None:
            # the service stages the reading for every tree; this answer uses it at once
            fresh = self.job.result() or {}
            self._speak(self.answer, lambda key: fresh[key] if key in fresh else self.read(key))
            return self.update()
        return status


DIALOG_NODES = (Reply,)

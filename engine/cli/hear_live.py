"""``vest hear --mic``: the robot's hearing live on a microphone, until Ctrl-C."""

from __future__ import annotations

import argparse
import json
from collections.abc import Callable

from engine.clock import Clock
from engine.dialogs.model import Dialog
from engine.hardware.config_file import load_robot_config
from engine.media.audio_devices import AlsaMicrophone
from engine.speech.listener import Heard, Listener
from engine.speech.recognizer import Recognizer
from engine.speech.vad import SileroVad, speech_detector


def listen_live(
    args: argparse.Namespace,
    recognizer: Recognizer,
    dialog: Dialog,
    clock: Clock,
    whole_turn: Callable[[str], bool],
) -> int:
    config = load_robot_config(args.hardware) if args.hardware is not None else None
    device = args.device or (config.audio.microphone if config else None) or "default"

    def show(heard: Heard) -> None:
        verdict = dialog.judge(heard.text) if heard.text else None
        match = verdict.match if verdict is not None else None
        answer = (
            match.rule.answer.source
            if match
            else (dialog.fallback.source if dialog.fallback else None)
        )
        if args.json:
            record = {
                "file": f"mic:{device}",
                "heard": heard.text or None,
                "rule": match.rule.id if match else None,
                "answer": answer,
            }
            print(json.dumps(record, ensure_ascii=False), flush=True)
        else:
            rule = f"rule {match.rule.id!r} ({match.score:.2f})" if match else "no rule"
            print(
                f"{heard.ended_s:9.2f}  heard {heard.text!r} -> {rule} -> says {answer!r}",
                flush=True,
            )

    detector = speech_detector(SileroVad(), children=args.hearing == "children")
    listener = Listener(detector, recognizer, clock, show, whole_turn=whole_turn)
    microphone = AlsaMicrophone(device, lambda audio: listener.hear(audio, clock.now()))
    microphone.start()  # AudioDeviceError names the missing card: exit 3
    print(f"listening on {device!r}; Ctrl-C stops", flush=True)
    never = clock.event()
    try:
        while microphone.error is None:  # Ctrl-C ends it (exit 130)
            clock.wait(never, 0.5)
    finally:
        microphone.close()
        listener.close()
    if microphone.error is not None:
        print(microphone.error)
        return 3
    return 0

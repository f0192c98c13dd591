"""The shipped model counts real hands: photographs of 28 people it never trained on
(examples/hands-real/held-out), "not sure" counted as wrong. The figure, per count and with
its confusion matrix, is in docs/vision-model-card.md and bench/bench_vision.py; this test
keeps a model that forgets real hands from shipping."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from engine.vision.classifier import DEFAULT_MODEL, HandModel
from engine.vision.preprocess import LABELS
from engine.vision_training.dataset import find_pictures
from engine.vision_training.training import evaluate_pictures

pytestmark = pytest.mark.models

HELD_OUT = Path(__file__).resolve().parents[2] / "examples" / "hands-real" / "held-out"


def test_the_shipped_model_counts_photographs_of_people_it_never_saw() -> None:
    pictures = find_pictures(HELD_OUT)
    assert len(pictures) == 160 and len({picture.session for picture in pictures}) == 28
    evaluation = evaluate_pictures(HandModel.load(DEFAULT_MODEL), pictures)
    assert evaluation.accuracy >= 0.90, evaluation.table()
    counted = np.diag(evaluation.matrix)[: len(LABELS)]
    shown = evaluation.matrix[: len(LABELS)].sum(axis=1)
    assert (counted / shown >= 0.75).all(), evaluation.table()  # no count left behind


def test_no_person_is_both_trained_on_and_held_out() -> None:
    trained = {picture.session for picture in find_pictures(HELD_OUT.parent / "train")}
    held_out = {picture.session for picture in find_pictures(HELD_OUT)}
    assert trained and held_out and not trained & held_out

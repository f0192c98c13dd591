"""Training the finger-count network on a folder of labelled pictures (``.[train]``).

Adam (learning rate 5e-4, warmed up over the first 300 steps, halved at 60 % and 85 % of
the epochs: at 1e-3 from the first step this deep network without normalisation often
dies into always answering "every count alike"), batches of 64, the
pictures augmented afresh every epoch (:func:`~engine.vision_training.dataset.augment`), then the
shared preprocessing. Pictures with no hand are trained towards the same probability for
every count, so the shipped model is "not sure" of an empty frame. The held-out pictures
are never trained on; after the last epoch the model is exported (ONNX, one file) with
its settings beside it, and measured on them through ONNX Runtime, as the robot runs it.
Runs on the CPU; seeds make a run repeatable on the same machine and thread count.
"""

from __future__ import annotations

import json
import logging
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from engine.errors import ConfigError
from engine.media.images import Frame
from engine.vision.classifier import MODEL_FORMAT, HandModel
from engine.vision.preprocess import LABELS, Preprocessing
from engine.vision_training.dataset import (
    NONE_INDEX,
    Picture,
    augment,
    batches,
    centred_inputs,
    find_pictures,
    load_pictures,
    network_inputs,
    split,
)
from engine.vision_training.evaluation import Evaluation

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class TrainingSettings:
    """``epochs`` passes over the training pictures, ``batch`` pictures a step, learning
    rate ``learning_rate``; ``held_out``: the share of pictures (or sessions) kept for the
    test; ``split_by``: "session" or "file"; ``threads``: PyTorch's CPU threads."""

    epochs: int = 16
    batch: int = 64
    learning_rate: float = 5e-4
    warmup_steps: int = 300
    held_out: float = 0.15
    split_by: str = "session"
    seed: int = 1
    threads: int = 2
    min_confidence: float = 0.6
    preprocessing: Preprocessing = field(default_factory=Preprocessing)
    start_from: Path | None = None
    """A model whose weights training starts from (else He initialisation)."""


@dataclass(frozen=True)
class TrainingResult:
    model: Path
    evaluation: Evaluation
    split: str
    trained_on: int
    held_out: int


def learning_rate_factor(step: int, steps_per_epoch: int, settings: TrainingSettings) -> float:
    """The share of the learning rate at ``step``: rising from 0.1 to 1 over the warm-up
    (at most a fifth of the run: a short fine-tuning run is not all warm-up), then halved
    at 60 % and again at 85 % of the epochs."""
    warmup = min(settings.warmup_steps, steps_per_epoch * settings.epochs // 5)
    if step < warmup:
        return 0.1 + 0.9 * step / warmup
    epoch = step / steps_per_epoch
    factor = 1.0
    for share in (0.6, 0.85):
        if epoch >= settings.epochs * share:
            factor *= 0.5
    return factor


def soft_targets(labels: npt.NDArray[np.int64]) -> npt.NDArray[np.float32]:
    """One-hot rows for the finger counts; the same share for every count for "no hand"."""
    targets = np.zeros((len(labels), len(LABELS)), dtype=np.float32)
    hands = labels < NONE_INDEX
    targets[np.flatnonzero(hands), labels[hands]] = 1.0
    targets[~hands] = 1.0 / len(LABELS)
    return targets


def train(
    data: Path | Sequence[Path],
    out: Path,
    settings: TrainingSettings,
    progress: Callable[[str], None] = lambda line: None,
) -> TrainingResult:
    """Train on the pictures in ``data`` (one labelled folder, or several: a lab's own, then
    photographs and drawn ones, say) and write ``out`` (.onnx) and its .json; ConfigError
    when a folder is not a labelled one. The held-out pictures come from the first folder
    only: the others are trained on whole (a model started from may have seen them, and a
    test on them would say more than it knows). With ``held_out`` 0 nothing is held out
    (the model is measured elsewhere: ``vest gesture eval``) and the evaluation is empty."""
    import torch

    from engine.vision_training.hand_network import HandNetwork, export_onnx, load_onnx_weights

    folders = [data] if isinstance(data, Path) else list(data)
    own = find_pictures(folders[0])
    others = [picture for folder in folders[1:] for picture in find_pictures(folder)]
    pictures = own + others
    if all(picture.label == NONE_INDEX for picture in pictures):
        raise ConfigError(
            f"{', '.join(map(str, folders))}: no pictures of a hand (0/ .. 5/ are empty); "
            "a model learns to count from them"
        )
    if settings.held_out > 0:  # only the first folder's: the others may be what a model
        train_set, test_set, how = split(  # it starts from already saw
            own, settings.held_out, settings.seed, by=settings.split_by
        )
        train_set += others
        if others:
            how += f", of {folders[0].name} only"
    else:
        train_set, test_set, how = list(pictures), [], "none held out"
    progress(
        f"{len(pictures)} pictures: training on {len(train_set)}, "
        f"holding out {len(test_set)} ({how})"
    )
    pre = settings.preprocessing
    train_images = load_pictures(train_set, pre)
    train_labels = np.array([p.label for p in train_set], dtype=np.int64)

    torch.manual_seed(settings.seed)
    torch.set_num_threads(max(1, settings.threads))
    rng = np.random.default_rng(settings.seed)
    network = HandNetwork()
    if settings.start_from is not None:
        try:
            load_onnx_weights(network, settings.start_from)
        except ValueError as error:
            raise ConfigError(str(error)) from None
        progress(f"starting from the weights of {settings.start_from}")
    optimiser = torch.optim.Adam(network.parameters(), lr=settings.learning_rate)
    steps_per_epoch = math.ceil(len(train_images) / settings.batch)
    schedule = torch.optim.lr_scheduler.LambdaLR(
        optimiser, lambda step: learning_rate_factor(step, steps_per_epoch, settings)
    )
    for epoch in range(1, settings.epochs + 1):
        network.train()
        total, right, seen = 0.0, 0, 0
        for index in batches(len(train_images), settings.batch, rng):
            windows = [augment(train_images[i], rng, pre) for i in index]
            inputs = torch.from_numpy(network_inputs(windows, pre))
            labels = train_labels[index]
            targets = torch.from_numpy(soft_targets(labels))
            scores = network(inputs)
            loss = -(targets * torch.log_softmax(scores, dim=1)).sum(dim=1).mean()
            optimiser.zero_grad()
            loss.backward()  # type: ignore[no-untyped-call]
            optimiser.step()
            schedule.step()
            hands = labels < NONE_INDEX
            said = scores.argmax(dim=1).numpy()
            right += int((said[hands] == labels[hands]).sum())
            seen += int(hands.sum())
            total += loss.item() * len(index)
        progress(
            f"epoch {epoch}/{settings.epochs}: loss {total / len(train_images):.3f}, "
            f"training accuracy {right / max(seen, 1):.1%}"
        )

    export_onnx(network, out)
    write_sidecar(out, settings, folders, how, len(train_set), len(test_set))
    evaluation = evaluate_pictures(
        HandModel.load(out, min_confidence=settings.min_confidence), test_set
    )
    sidecar = out.with_suffix(".json")
    document = json.loads(sidecar.read_text(encoding="utf-8"))
    document["training"]["held_out_evaluation"] = evaluation.to_json() if test_set else None
    sidecar.write_text(json.dumps(document, indent=2) + "\n", encoding="utf-8")
    return TrainingResult(out, evaluation, how, len(train_set), len(test_set))


def write_sidecar(
    out: Path,
    settings: TrainingSettings,
    data: Sequence[Path],
    how: str,
    trained: int,
    held: int,
) -> None:
    """The model's settings beside it: what the robot needs, and how it was made."""
    import torch

    document: dict[str, Any] = {
        "format": MODEL_FORMAT,
        "labels": list(LABELS),
        "preprocessing": settings.preprocessing.to_json(),
        "training": {
            "data": [folder.name for folder in data],
            "pictures": trained,
            "held_out": held,
            "split": how,
            "epochs": settings.epochs,
            "batch": settings.batch,
            "learning_rate": settings.learning_rate,
            "warmup_steps": settings.warmup_steps,
            "seed": settings.seed,
            "started_from": None if settings.start_from is None else settings.start_from.name,
            "torch": torch.__version__,
        },
    }
    out.with_suffix(".json").write_text(json.dumps(document, indent=2) + "\n", encoding="utf-8")


def evaluate_images(
    model: HandModel, images: Sequence[Frame], labels: npt.NDArray[np.int64], batch: int = 256
) -> Evaluation:
    """The model on whole pictures (the crop rule, then the network), as the robot sees them."""
    scores = [
        model.probabilities(centred_inputs(images[start : start + batch], model.settings))
        for start in range(0, len(images), batch)
    ]
    probabilities = np.concatenate(scores) if scores else np.zeros((0, len(LABELS)), np.float32)
    return Evaluation.of(probabilities, labels, model.min_confidence)


def evaluate_pictures(model: HandModel, pictures: Sequence[Picture]) -> Evaluation:
    images = load_pictures(pictures, model.settings)
    labels = np.array([p.label for p in pictures], dtype=np.int64)
    return evaluate_images(model, images, labels)

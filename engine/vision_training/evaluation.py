"""How well a model counts fingers: accuracy and a confusion matrix, printed and drawn.

Rows are what the pictures show (0..5 fingers, then no hand); columns what the model
said (0..5, then "not sure": its best label below ``min_confidence``). Accuracy counts
the pictures of a hand read right; "not sure" on a hand is wrong, on no hand it is right.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import numpy.typing as npt

from engine.errors import ConfigError
from engine.vision.preprocess import LABELS

ROWS = (*(str(label) for label in LABELS), "none")
COLUMNS = (*(str(label) for label in LABELS), "not sure")


@dataclass(frozen=True)
class Evaluation:
    """``matrix[true][said]`` counts (7 x 7, see the module's doc)."""

    matrix: npt.NDArray[np.int64]

    @classmethod
    def of(
        cls,
        probabilities: npt.NDArray[np.float32],
        labels: npt.NDArray[np.int64],
        min_confidence: float,
    ) -> Evaluation:
        """From each picture's probabilities (N, 6) and its label index (0..5, 6 none)."""
        said = np.argmax(probabilities, axis=1)
        said = np.where(probabilities.max(axis=1) >= min_confidence, said, len(LABELS))
        matrix = np.zeros((len(ROWS), len(COLUMNS)), dtype=np.int64)
        np.add.at(matrix, (labels, said), 1)
        return cls(matrix)

    @property
    def hands(self) -> int:
        return int(self.matrix[: len(LABELS)].sum())

    @property
    def accuracy(self) -> float:
        """Pictures of a hand with the right count, 0..1 (0 when there are none)."""
        right = int(np.trace(self.matrix[: len(LABELS), : len(LABELS)]))
        return right / self.hands if self.hands else 0.0

    @property
    def sure_accuracy(self) -> float:
        """Of the hands the model was sure of, the share it counted right."""
        sure = int(self.matrix[: len(LABELS), : len(LABELS)].sum())
        right = int(np.trace(self.matrix[: len(LABELS), : len(LABELS)]))
        return right / sure if sure else 0.0

    @property
    def empty_unsure(self) -> float | None:
        """Of the pictures with no hand, the share read as "not sure" (None: there were none)."""
        empty = int(self.matrix[len(LABELS)].sum())
        return int(self.matrix[len(LABELS), len(LABELS)]) / empty if empty else None

    def to_json(self) -> dict[str, Any]:
        return {
            "hands": self.hands,
            "accuracy": round(self.accuracy, 4),
            "sure_accuracy": round(self.sure_accuracy, 4),
            "no_hand_read_as_not_sure": None
            if self.empty_unsure is None
            else round(self.empty_unsure, 4),
            "rows": list(ROWS),
            "columns": list(COLUMNS),
            "matrix": self.matrix.tolist(),
        }

    def table(self) -> str:
        """The matrix as aligned text, rows "shows", columns "said"."""
        width = max(6, len(str(int(self.matrix.max()))) + 1)
        head = "shows \\ said " + "".join(f"{name:>{width + 3}}" for name in COLUMNS)
        lines = [head]
        for name, row in zip(ROWS, self.matrix, strict=True):
            lines.append(f"{name:>12} " + "".join(f"{int(n):>{width + 3}}" for n in row))
        return "\n".join(lines)

    def summary(self) -> str:
        line = (
            f"accuracy {self.accuracy:.1%} on {self.hands} pictures of a hand "
            f"({self.sure_accuracy:.1%} of those it was sure of)"
        )
        if self.empty_unsure is not None:
            line += f"; no hand read as not sure {self.empty_unsure:.1%}"
        return line

    def write_png(self, path: Path, title: str) -> None:
        """The matrix drawn as a heat map with its counts; OSError when it cannot be written."""
        cell, left, top = 64, 110, 70
        rows, columns = self.matrix.shape
        image = np.full((top + rows * cell + 20, left + columns * cell + 20, 3), 255, np.uint8)
        shares = self.matrix / np.maximum(self.matrix.sum(axis=1, keepdims=True), 1)
        font = cv2.FONT_HERSHEY_SIMPLEX
        cv2.putText(image, title[:60], (10, 22), font, 0.55, (0, 0, 0), 1, cv2.LINE_AA)
        cv2.putText(image, "said ->", (left, 52), font, 0.45, (80, 80, 80), 1, cv2.LINE_AA)
        for column, name in enumerate(COLUMNS):
            x = left + column * cell + 6
            cv2.putText(image, name, (x, top - 4), font, 0.42, (0, 0, 0), 1, cv2.LINE_AA)
        for row, name in enumerate(ROWS):
            y = top + row * cell
            cv2.putText(image, f"shows {name}", (6, y + cell // 2 + 5), font, 0.45, (0, 0, 0), 1)
            for column in range(columns):
                x = left + column * cell
                level = int(255 - 200 * shares[row, column])
                colour = (255, level, level) if row == column else (level, level, 255)
                cv2.rectangle(image, (x, y), (x + cell - 2, y + cell - 2), colour, -1)
                text = str(int(self.matrix[row, column]))
                cv2.putText(image, text, (x + 8, y + cell // 2 + 5), font, 0.5, (0, 0, 0), 1)
        if not cv2.imwrite(str(path), image):
            raise ConfigError(f"{path}: cannot write the picture there")

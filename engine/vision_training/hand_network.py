"""The paper's finger-count CNN (table 2) in PyTorch: for training only (``.[train]``).

Seven blocks of a 3 x 3 convolution ("same" padding) + ReLU + 2 x 2 max-pool with 8, 16,
32, 64, 128, 256 and 512 filters take the 1 x 128 x 128 edge image down to 512 x 1 x 1;
a fully connected layer 512 -> 128 + ReLU + dropout and one 128 -> 6 give a score per
finger count, and the exported model ends in the softmax. 1,640,006 parameters, about
30 M multiply-adds a frame. docs/vision.md maps each row of the table to a layer and says
what the paper leaves open (the dropout rate is ours: 0.5).

PyTorch's default initialisation leaves this deep, narrow-at-the-start network at chance;
He initialisation (for ReLU) lets it learn.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import torch
from torch import nn

from engine.vision.preprocess import LABELS, SIDE_PX

FILTERS = (8, 16, 32, 64, 128, 256, 512)
HIDDEN = 128
DROPOUT = 0.5
INPUT_NAME, OUTPUT_NAME = "image", "probabilities"


class HandNetwork(nn.Module):
    """Table 2: the edge image (N, 1, 128, 128), values 0/1, to a score per label (N, 6)
    (logits: :class:`WithSoftmax` turns them into probabilities for export)."""

    def __init__(self, classes: int = len(LABELS), dropout: float = DROPOUT) -> None:
        super().__init__()
        layers: list[nn.Module] = []
        channels = 1
        for filters in FILTERS:
            layers += [
                nn.Conv2d(channels, filters, kernel_size=3, padding=1),
                nn.ReLU(inplace=True),
                nn.MaxPool2d(2),
            ]
            channels = filters
        self.features = nn.Sequential(*layers)
        self.classifier = nn.Sequential(
            nn.Flatten(),
            nn.Linear(channels, HIDDEN),
            nn.ReLU(inplace=True),
            nn.Dropout(dropout),
            nn.Linear(HIDDEN, classes),
        )
        for module in self.modules():
            if isinstance(module, nn.Conv2d | nn.Linear):
                nn.init.kaiming_normal_(module.weight, nonlinearity="relu")
                if module.bias is not None:
                    nn.init.zeros_(module.bias)

    def forward(self, images: torch.Tensor) -> torch.Tensor:
        result: torch.Tensor = self.classifier(self.features(images))
        return result


class WithSoftmax(nn.Module):
    """The network as it ships: probabilities, not logits."""

    def __init__(self, network: HandNetwork) -> None:
        super().__init__()
        self.network = network

    def forward(self, images: torch.Tensor) -> torch.Tensor:
        result: torch.Tensor = torch.softmax(self.network(images), dim=1)
        return result


def parameter_count(network: nn.Module) -> int:
    return sum(int(p.numel()) for p in network.parameters())


def load_onnx_weights(network: HandNetwork, path: Path) -> None:
    """Start ``network`` from the weights of a model exported by :func:`export_onnx` (the
    shipped one, or a lab's): to train further, or to fit it to a lab's own pictures.
    ValueError naming the file when it is not this network."""
    import onnx
    from onnx import numpy_helper

    try:
        graph = onnx.load(str(path)).graph
    except Exception as error:  # onnx raises its own decode errors
        raise ValueError(f"{path}: not an ONNX model ({error})") from None
    weights = {item.name: numpy_helper.to_array(item) for item in graph.initializer}
    state = WithSoftmax(network).state_dict()
    missing = [name for name in state if name not in weights]
    wrong = [n for n in state if n in weights and tuple(weights[n].shape) != tuple(state[n].shape)]
    if missing or wrong:
        raise ValueError(f"{path}: not the table-2 network this trains ({(missing + wrong)[0]})")
    WithSoftmax(network).load_state_dict(
        {name: torch.from_numpy(weights[name].copy()) for name in state}
    )


def export_onnx(network: HandNetwork, path: Path) -> None:
    """The network with its softmax as one ONNX file (weights inside, any batch size):
    input ``image`` (N, 1, 128, 128) float32, output ``probabilities`` (N, 6)."""
    shipped = WithSoftmax(network).eval()
    example = torch.zeros(1, 1, SIDE_PX, SIDE_PX)
    path.parent.mkdir(parents=True, exist_ok=True)
    with warnings.catch_warnings():  # it says it is the older exporter: we chose it
        warnings.simplefilter("ignore", DeprecationWarning)
        torch.onnx.export(
            shipped,
            (example,),
            str(path),
            input_names=[INPUT_NAME],
            output_names=[OUTPUT_NAME],
            dynamic_axes={INPUT_NAME: {0: "batch"}, OUTPUT_NAME: {0: "batch"}},
            opset_version=17,
            dynamo=False,  # the TorchScript exporter: one self-contained file
        )

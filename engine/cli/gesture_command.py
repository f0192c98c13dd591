"""Count the fingers in pictures, and make a lab's own finger-count model.

  vest gesture IMAGE... [--model FILE] [--json] [--crop X,Y,W]
      whether each picture shows a hand held up, where, and how many fingers: the hand is
      found anywhere in a camera frame (MediaPipe's palm detector and hand landmarks) and
      counted from its landmarks; a picture smaller than 128 x 128 px is a close-up,
      counted by the paper's network (--model); --crop X,Y,W gives the paper's network the
      window W px wide at X,Y instead
  vest gesture record DATA --label N [--frames K] [--camera DEV]   K frames from the camera
  vest gesture record DATA [--camera DEV]      a frame each time you type its label + Enter
  vest gesture record DATA --label N --from FOLDER       pictures you already have
  vest gesture generate DATA --count N [--seed S] [--style studio|variant]
  vest gesture train DATA... -o MODEL.onnx [--epochs E] [--split session|file]
      [--held-out SHARE] [--preprocess gray|edges] [--init MODEL.onnx]
  vest gesture eval DATA --model MODEL.onnx [--json]

DATA is a folder with 0/ .. 5/ (pictures showing that many fingers) and none/ (no hand).
Training needs PyTorch: ``pip install -e .[train]`` (docs/vision.md).
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path

from engine.cli.output import writable_folder

ACTIONS = ("classify", "record", "generate", "train", "eval")
STYLE_NAMES = ("studio", "wallpaper", "varied", "variant")
"""The hand generator's styles (engine/vision_training/synthetic_hands.py; not imported here)."""
PREPROCESS_MODES = ("gray", "edges")
"""How a picture becomes the network's input (engine/vision/preprocess.py's MODES)."""


def with_action(argv: Sequence[str]) -> list[str]:
    """``vest gesture IMAGE...`` is ``vest gesture classify IMAGE...``."""
    words = list(argv)
    if len(words) >= 2 and words[0] == "gesture" and words[1] not in (*ACTIONS, "-h", "--help"):
        words.insert(1, "classify")
    return words


def _crop(text: str) -> tuple[int, int, int]:
    parts = text.split(",")
    try:
        x, y, w = (int(part) for part in parts)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"must be X,Y,W in px (e.g. 256,116,128), got {text!r}"
        ) from None
    if x < 0 or y < 0 or w < 8:
        raise argparse.ArgumentTypeError(
            f"X and Y must be 0 or more and W at least 8, got {text!r}"
        )
    return x, y, w


def _positive(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a whole number, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be 1 or more, got {value}")
    return value


def _seed(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a whole number, got {text!r}") from None
    if not 0 <= value < 2**32:
        raise argparse.ArgumentTypeError(f"must be 0 .. 4294967295, got {value}")
    return value


def _share(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number, got {text!r}") from None
    if not 0.0 < value < 1.0:
        raise argparse.ArgumentTypeError(f"must be between 0 and 1, got {text}")
    return value


def _held_out(text: str) -> float:
    """A share to hold out: 0 (none) or between 0 and 1."""
    try:
        nothing = float(text) == 0.0
    except ValueError:
        nothing = False
    return 0.0 if nothing else _share(text)


def _label(text: str) -> str:
    from engine.vision_training.dataset import FOLDERS

    if text not in FOLDERS:
        raise argparse.ArgumentTypeError(f"must be one of {', '.join(FOLDERS)}, got {text!r}")
    return text


def _model_argument(parser: argparse.ArgumentParser, required: bool = False) -> None:
    parser.add_argument(
        "--model",
        type=Path,
        default=None,
        required=required,
        metavar="FILE.onnx",
        help="a model (its .json beside it)" + ("" if required else "; default: the project's"),
    )


def add_arguments(parser: argparse.ArgumentParser) -> None:
    actions = parser.add_subparsers(dest="action", metavar="ACTION")
    classify = actions.add_parser("classify", help="count the fingers in pictures (the default)")
    classify.add_argument("images", nargs="+", type=Path, metavar="IMAGE")
    _model_argument(classify)
    classify.add_argument("--json", action="store_true", help="one JSON object per picture")
    classify.add_argument(
        "--crop",
        type=_crop,
        default=None,
        metavar="X,Y,W",
        help="the paper's window for its network, instead of finding the hand",
    )

    record = actions.add_parser("record", help="add labelled pictures to a data folder")
    record.add_argument("data", type=Path, metavar="DATA")
    record.add_argument("--label", type=_label, default=None, help="0..5 or none")
    record.add_argument("--frames", type=_positive, default=None, help="frames to take")
    record.add_argument("--camera", default="0", help="an index or a path (default: 0)")
    record.add_argument(
        "--from", dest="source", type=Path, default=None, metavar="FOLDER", help="pictures to add"
    )
    record.add_argument("--session", default=None, help="the session's name (default: the time)")

    generate = actions.add_parser("generate", help="draw labelled hands (the project's data)")
    generate.add_argument("data", type=Path, metavar="DATA")
    generate.add_argument("--count", type=_positive, required=True)
    generate.add_argument("--seed", type=_seed, default=1)
    generate.add_argument("--style", choices=STYLE_NAMES, default="studio")

    train = actions.add_parser("train", help="train the table-2 network (needs .[train])")
    train.add_argument(
        "data",
        type=Path,
        nargs="+",
        metavar="DATA",
        help="folders of pictures; the held-out test comes from the first only",
    )
    train.add_argument("-o", "--output", type=Path, required=True, metavar="MODEL.onnx")
    train.add_argument("--epochs", type=_positive, default=16)
    train.add_argument("--batch", type=_positive, default=64)
    train.add_argument("--seed", type=_seed, default=1)
    train.add_argument(
        "--held-out", type=_held_out, default=0.15, help="share held out (0: none; below 1)"
    )
    train.add_argument(
        "--preprocess",
        choices=PREPROCESS_MODES,
        default=None,
        help="edges (the paper's and the shipped model's) or gray; default: the --init "
        "model's, else edges",
    )
    train.add_argument("--split", choices=("session", "file"), default="session")
    train.add_argument("--threads", type=_positive, default=2, help="CPU threads")
    train.add_argument(
        "--learning-rate", type=_share, default=5e-4, metavar="RATE", help="Adam's (default 5e-4)"
    )
    train.add_argument(
        "--init",
        type=Path,
        default=None,
        metavar="MODEL.onnx",
        help="start from this model's weights (train further, or fit it to your pictures)",
    )
    train.add_argument("--matrix", type=Path, default=None, help="confusion matrix PNG")

    evaluate = actions.add_parser("eval", help="measure a model on labelled pictures")
    evaluate.add_argument("data", type=Path, metavar="DATA")
    _model_argument(evaluate, required=True)
    evaluate.add_argument("--json", action="store_true")
    evaluate.add_argument("--matrix", type=Path, default=None, help="confusion matrix PNG")


def main(args: argparse.Namespace) -> int:
    from engine.errors import UsageError

    if args.action is None:
        raise UsageError("name pictures to classify, or an action: " + ", ".join(ACTIONS[1:]))
    if args.action == "classify":
        return _classify(args)
    if args.action == "record":
        from engine.cli.gesture_record import record

        return record(args)
    if args.action == "generate":
        return _generate(args)
    if args.action == "train":
        return _train(args)
    return _evaluate(args)


def _classify(args: argparse.Namespace) -> int:
    from engine.cli.output import shown, tell
    from engine.media.images import read_image
    from engine.vision.classifier import DEFAULT_MODEL, HandModel
    from engine.vision.hand_finder import HandFinder
    from engine.vision.preprocess import fills_window, scaled_window

    model = HandModel.load(args.model or DEFAULT_MODEL)
    finder = HandFinder.load(close_ups=model)
    side = model.settings.side_px
    failed = 0
    for path in args.images:
        try:
            image = read_image(path)
            if args.crop is not None:  # the paper's window, as its network reads it
                image = scaled_window(image, *args.crop, side_px=side)
                reading = model.read(image)
            else:
                finder.forget()  # each picture on its own
                reading = finder.read(image)
            close_up = not fills_window(image, model.settings)
        except ValueError as error:
            text = str(error)
            tell(text if str(path) in text else f"{path}: {text}")
            failed += 1
            continue
        size = f"{image.shape[1]}x{image.shape[0]}"
        if args.json:
            print(json.dumps({"file": str(path), **reading.to_json(), "close_up": close_up}))
            continue
        if not reading.present:
            said = "no hand held up"
        elif reading.fingers is None:
            said = "a hand, its count not sure"
        else:
            said = f"{reading.fingers} finger" + ("" if reading.fingers == 1 else "s")
        note = ""
        if close_up:
            note = f" (a {size} px close-up, counted by the paper's network)"
        elif reading.box is not None and args.crop is None:
            x, y, width, height = reading.box
            note = f" (the hand at {x},{y}, {width}x{height} px, in a {size} px picture)"
        sure = f" ({reading.confidence:.0%})" if reading.present else ""
        print(f"{shown(str(path))}: {said}{sure}{note}")
    return 1 if failed else 0


def _generate(args: argparse.Namespace) -> int:
    from engine.vision_training.synthetic_hands import write_dataset

    writable_folder(args.data)
    written = write_dataset(args.data, args.count, args.seed, style=args.style)
    print(f"{written} pictures ({args.style}, seed {args.seed}) in {args.data}")
    return 0


def _train(args: argparse.Namespace) -> int:
    from engine.errors import ConfigError, DeviceError

    try:
        import torch  # noqa: F401
    except ImportError:
        raise DeviceError(
            None, "training needs PyTorch: pip install -e '.[train]' (see docs/vision.md)"
        ) from None
    from engine.files.yaml_source import resolved
    from engine.vision.classifier import HandModel
    from engine.vision.preprocess import Preprocessing
    from engine.vision_training.training import TrainingSettings, train

    if args.output.suffix != ".onnx":
        raise ConfigError(f"{args.output}: the model's file name must end in .onnx")
    matrix = args.matrix or args.output.with_suffix(".matrix.png")
    for path in (args.output, args.output.with_suffix(".json"), matrix):
        writable_folder(path.parent)  # before the training, not after it
        if path.exists() and not path.is_file():  # a folder, a FIFO: found out after hours
            raise ConfigError(f"{path}: not a file the training can write; name another")
    seen: set[Path] = set()
    twice = None
    for folder in args.data:
        twice = twice or (folder if resolved(folder) in seen else None)
        seen.add(resolved(folder))
    if twice is not None:  # its pictures would count twice, and be trained and tested on
        raise ConfigError(f"{twice}: named twice; name each folder of pictures once")
    pre = Preprocessing()
    if args.init is not None:  # a lab's retraining reads pictures as the model it starts from
        pre = HandModel.load(args.init).settings
    if args.preprocess is not None:
        if args.init is not None and args.preprocess != pre.mode:
            print(
                f"note: {args.init} reads pictures as {pre.mode}; training it on "
                f"{args.preprocess} starts from weights made for another input",
                file=sys.stderr,
            )
        pre = replace(pre, mode=args.preprocess)
    settings = TrainingSettings(
        preprocessing=pre,
        epochs=args.epochs,
        batch=args.batch,
        seed=args.seed,
        held_out=args.held_out,
        split_by=args.split,
        threads=args.threads,
        learning_rate=args.learning_rate,
        start_from=args.init,
    )
    result = train(args.data, args.output, settings, lambda line: print(line, flush=True))
    sidecar = args.output.with_suffix(".json")
    if not result.held_out:
        print(f"model: {args.output} (settings in {sidecar}); nothing held out: measure it with")
        print(f"  vest gesture eval PICTURES --model {args.output}")
        return 0
    if not result.evaluation.hands:  # 0.0 % of nothing would read as a model that fails
        print(
            f"model: {args.output} (settings in {sidecar}); the held-out pictures show no "
            "hand: hold out more (--held-out), or measure it with vest gesture eval"
        )
        return 0
    print(result.evaluation.table())
    print(f"held out: {result.evaluation.summary()}")
    result.evaluation.write_png(matrix, f"{args.output.name}: held out ({result.split})")
    print(f"model: {args.output} (settings in {sidecar}); matrix: {matrix}")
    return 0


def _evaluate(args: argparse.Namespace) -> int:
    from engine.vision.classifier import HandModel
    from engine.vision_training.dataset import find_pictures
    from engine.vision_training.training import evaluate_pictures

    model = HandModel.load(args.model)
    evaluation = evaluate_pictures(model, find_pictures(args.data))
    if args.json:
        print(json.dumps(evaluation.to_json()))
    else:
        print(evaluation.table())
        print(evaluation.summary())
    if args.matrix is not None:
        writable_folder(args.matrix.parent)
        evaluation.write_png(args.matrix, f"{args.model.name} on {args.data.name}")
    sys.stdout.flush()
    return 0

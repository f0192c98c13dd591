"""Inputs that are too big, or not files: refused with a clear line, never a hang, a
traceback or gigabytes of memory.

A small file can hold a huge picture (its header says how big; nothing is decoded past
it), a WAV's size does not bound its samples (the rate and the length do), a FIFO named as
a file would be waited on for ever (every file a person names is read by the one safe
reader), and a number in a model's settings can make one frame take minutes.
"""

from __future__ import annotations

import io
import os
import struct
import wave
import zlib
from pathlib import Path

import numpy as np
import pytest

from engine.cli import main
from engine.errors import ConfigError
from engine.media.audio import AudioFileError, read_wav
from engine.media.image_size import image_size
from engine.media.images import read_image
from engine.services.done_commands import DoneCommands
from engine.vision.preprocess import Preprocessing, load_settings

ROOT = Path(__file__).resolve().parents[1]


def png_header(width: int, height: int) -> bytes:
    """A PNG's signature and header chunk (and an empty end): enough to say its size."""
    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    chunk = b"IHDR" + header
    ihdr = struct.pack(">I", len(header)) + chunk + struct.pack(">I", zlib.crc32(chunk))
    return b"\x89PNG\r\n\x1a\n" + ihdr + struct.pack(">I", 0) + b"IEND" + b"\xaeB`\x82"


def test_a_small_png_of_a_huge_picture_is_refused_by_its_header(tmp_path: Path, capsys) -> None:
    huge = tmp_path / "huge.png"
    huge.write_bytes(png_header(30000, 30000))  # under 100 bytes, 2.7 GB decoded
    with pytest.raises(ValueError, match="a 30000x30000 px picture; at most 8192x8192"):
        read_image(huge)
    assert main(["gesture", str(huge)]) != 0
    assert "30000x30000 px" in capsys.readouterr().err


def test_the_header_gives_each_format_s_size() -> None:
    assert image_size(png_header(640, 480)) == (640, 480)
    bmp = b"BM" + b"\x00" * 16 + struct.pack("<ii", 320, -240)
    assert image_size(bmp) == (320, 240)
    assert image_size(b"GIF89a" + struct.pack("<HH", 10, 20)) == (10, 20)
    jpeg = b"\xff\xd8\xff\xe0\x00\x04ab\xff\xc0\x00\x0b\x08" + struct.pack(">HH", 90, 160)
    assert image_size(jpeg) == (160, 90)
    assert image_size(b"not a picture at all") is None
    assert image_size(b"\x89PNG\r\n\x1a\n") is None  # cut short


def test_an_os2_bitmap_is_measured_by_its_own_header_and_read(tmp_path: Path) -> None:
    """OS/2's BMP header keeps the size in two 16-bit numbers, not two 32-bit ones."""
    width, height = 100, 60
    pixels = b"\x80" * ((width * 3 + 3) // 4 * 4 * height)
    core = struct.pack("<IHHHH", 12, width, height, 1, 24)
    picture = tmp_path / "os2.bmp"
    picture.write_bytes(b"BM" + struct.pack("<IHHI", 26 + len(pixels), 0, 0, 26) + core + pixels)
    assert image_size(picture.read_bytes()) == (100, 60)
    assert read_image(picture).shape == (60, 100, 3)


def wav(path: Path, rate: int, seconds: float, channels: int = 1) -> Path:
    frames = int(rate * seconds)
    samples = (np.sin(np.arange(frames * channels) / 20.0) * 8000).astype("<i2")
    out = io.BytesIO()
    with wave.open(out, "wb") as writer:
        writer.setnchannels(channels)
        writer.setsampwidth(2)
        writer.setframerate(rate)
        writer.writeframes(samples.tobytes())
    path.write_bytes(out.getvalue())
    return path


def test_a_wav_at_a_rate_no_microphone_records_is_refused(tmp_path: Path) -> None:
    with pytest.raises(AudioFileError, match="sample rate 384000 Hz; use 8000 to 96000 Hz"):
        read_wav(wav(tmp_path / "fast.wav", 384000, 0.1))


def test_a_wav_longer_than_ten_minutes_is_refused(tmp_path: Path) -> None:
    with pytest.raises(AudioFileError, match="more than 600 s of audio"):
        read_wav(wav(tmp_path / "long.wav", 8000, 601))


def test_a_stereo_wav_is_read_as_mono_and_resampled_to_its_length(tmp_path: Path) -> None:
    audio = read_wav(wav(tmp_path / "stereo.wav", 48000, 2.0, channels=2))
    assert (audio.rate_hz, len(audio.samples)) == (48000, 96000)
    assert len(audio.resampled(16000).samples) == 32000


def test_a_fifo_named_as_a_model_s_settings_or_the_done_record_never_hangs(
    tmp_path: Path,
) -> None:
    settings = tmp_path / "model.json"
    os.mkfifo(settings)
    with pytest.raises(ConfigError, match="not a regular file"):
        load_settings(settings)
    done = tmp_path / "robot.token.done.json"
    os.mkfifo(done)
    assert DoneCommands(done).damaged is not None  # set aside, not waited on


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("blur_px", 99999),
        ("block_px", 4001),
        ("side_px", 100000),
        ("blur_sigma", 1e9),
        ("crop_x", 10**9),
        ("blur_px", True),
        ("threshold_c", "4"),
    ],
)
def test_a_model_s_settings_with_numbers_past_any_frame_are_refused(
    field: str, value: object
) -> None:
    with pytest.raises(ConfigError, match=field):
        Preprocessing.from_json({field: value}, "model.json")


@pytest.mark.parametrize(
    "text",
    ["[" * 20_000 + "]" * 20_000, '{"blur_px": ' + "9" * 5000 + "}"],
    ids=["nested past reading", "a 5,000-digit number"],
)
def test_settings_that_python_cannot_read_as_json_are_named(tmp_path: Path, text: str) -> None:
    settings = tmp_path / "model.json"
    settings.write_text(text)
    with pytest.raises(ConfigError, match=r"model\.json: not readable JSON"):
        load_settings(settings)

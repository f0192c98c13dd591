"""The face's RGB LEDs on a simulated PCA9685."""

from __future__ import annotations

import pytest

from engine.clock import VirtualClock
from engine.drivers.pca9685 import PCA9685
from engine.drivers.rgb_leds import RgbLeds, color_to_rgb
from engine.sim.i2c_bus import SimI2CBus
from engine.sim.pca9685 import SimPCA9685

FACE = {"left_eye": (0, 1, 2), "right_eye": (3, 4, 5), "mouth": (6, 7, 8)}


@pytest.fixture
def chip(clock: VirtualClock) -> SimPCA9685:
    return SimPCA9685(clock)


@pytest.fixture
def pwm(clock: VirtualClock, chip: SimPCA9685) -> PCA9685:
    bus = SimI2CBus(clock)
    bus.attach(chip)
    return PCA9685(bus, clock=clock)


def lit(chip: SimPCA9685, channels: tuple[int, int, int]) -> tuple[float, ...]:
    return tuple(chip.duty(channel) for channel in channels)


def approx_rgb(rgb: tuple[float, float, float]):
    return pytest.approx(rgb, abs=1 / 4096)


def test_a_hug_turns_the_whole_face_pink(chip, pwm):
    face = RgbLeds(pwm, FACE)
    face.set_color("all", "pink")
    pink = color_to_rgb("pink")
    for channels in FACE.values():
        assert lit(chip, channels) == approx_rgb(pink)
    assert pink[0] == 1.0 and pink[0] > pink[2] > pink[1]  # mostly red, some blue, less green


def test_one_eye_turns_blue_and_the_rest_stays_dark(chip, pwm):
    face = RgbLeds(pwm, FACE)
    face.set_color("left_eye", (0.0, 0.0, 1.0))
    assert lit(chip, FACE["left_eye"]) == (0.0, 0.0, 1.0)
    assert lit(chip, FACE["right_eye"]) == (0.0, 0.0, 0.0)
    assert face.color("left_eye") == (0.0, 0.0, 1.0)


def test_common_anode_leds_are_lit_by_a_low_output(chip, pwm):
    face = RgbLeds(pwm, FACE, common_anode=True)
    face.set_color("mouth", "red")
    assert lit(chip, FACE["mouth"]) == (0.0, 1.0, 1.0)
    face.off()
    assert lit(chip, FACE["mouth"]) == (1.0, 1.0, 1.0)


def test_off_darkens_every_led(chip, pwm):
    face = RgbLeds(pwm, FACE)
    face.set_color("all", "white")
    face.off()
    assert all(chip.duty(channel) == 0.0 for channels in FACE.values() for channel in channels)


def test_an_unknown_led_name_lists_the_leds(pwm):
    face = RgbLeds(pwm, FACE)
    with pytest.raises(ValueError, match=r"no LED named 'nose'.*left_eye, right_eye, mouth, all"):
        face.set_color("nose", "red")


@pytest.mark.parametrize("rgb", [(1.2, 0.0, 0.0), (0.0, -0.1, 0.0), (0.5, 0.5)])
def test_colours_outside_0_to_1_are_refused(pwm, rgb):
    face = RgbLeds(pwm, FACE)
    with pytest.raises(ValueError, match="three fractions"):
        face.set_color("mouth", rgb)  # type: ignore[arg-type]


def test_two_leds_cannot_share_a_channel(pwm):
    with pytest.raises(ValueError, match="channel 2 is already used by LED 'a'"):
        RgbLeds(pwm, {"a": (0, 1, 2), "b": (2, 3, 4)})
    with pytest.raises(ValueError, match="got 16"):
        RgbLeds(pwm, {"a": (14, 15, 16)})


def test_colour_names_and_hex():
    assert color_to_rgb("off") == (0.0, 0.0, 0.0)
    assert color_to_rgb("Blue") == (0.0, 0.0, 1.0)
    assert color_to_rgb(" #FF8000 ") == (1.0, pytest.approx(128 / 255), 0.0)
    for name in ("pink", "red", "green", "white", "orange", "yellow", "purple"):
        assert all(0.0 <= value <= 1.0 for value in color_to_rgb(name))
    with pytest.raises(ValueError, match=r"unknown color 'chartreuse'.*pink"):
        color_to_rgb("chartreuse")
    with pytest.raises(ValueError, match="#12345"):
        color_to_rgb("#12345")

"""The VL53L0X reference SPADs: which to enable, from the chip's factory NVM, as ST does.

The chip measures its own VCSEL's light on a reference array of 48 single-photon
avalanche diodes (SPADs) beside the return array. At the factory ST stores in NVM how many
reference SPADs this part needs, of which kind (the first 12 of the array are
non-aperture SPADs, the other 36 aperture SPADs, smaller and seeing less light), and a map
of the ones that work. ST's ``VL53L0X_set_reference_spads`` enables that many working
SPADs of that kind, in array order, starting with the first of the kind; an NVM whose
count does not fit its kind is invalid (ST then runs its reference SPAD management, a
calibration on a target; we do not: the chip is refused instead).

The NVM words, read through ST's handshake on register pages 6 and 7, are: 0x6B (bits
14:8 the count, bit 15 the kind, 1 = aperture) and 0x24, 0x25 (the 6-byte map of working
SPADs, most significant byte first; bit n of byte k is SPAD 8k + n).
"""

from __future__ import annotations

from dataclasses import dataclass

SPAD_MAP_BYTES = 6
SPADS = 8 * SPAD_MAP_BYTES
FIRST_APERTURE_SPAD = 12  # with the array's start at 0xB4 (GLOBAL_CONFIG_REF_EN_START_SELECT)
MAX_NON_APERTURE_SPADS = 12
MAX_APERTURE_SPADS = 32


@dataclass(frozen=True)
class ReferenceSpads:
    """The factory data of one chip's reference SPADs."""

    count: int  # how many to enable
    aperture: bool  # their kind
    good_map: bytes  # 6 bytes: bit n of byte k set when SPAD 8k + n works


def from_nvm_words(spad_info: int, map_head: int, map_tail: int) -> ReferenceSpads:
    """The reference SPADs from NVM words 0x6B, 0x24 and 0x25 (32-bit each)."""
    good_map = map_head.to_bytes(4, "big") + (map_tail >> 16).to_bytes(2, "big")
    return ReferenceSpads((spad_info >> 8) & 0x7F, bool(spad_info & 0x8000), good_map)


def select_reference_spads(spads: ReferenceSpads) -> bytes:
    """The 6 bytes for GLOBAL_CONFIG_SPAD_ENABLES_REF_0..5 (0xB0..0xB5).

    ValueError when the NVM's count does not fit its kind, or when the map has too few
    working SPADs of that kind.
    """
    kind = "aperture" if spads.aperture else "non-aperture"
    limit = MAX_APERTURE_SPADS if spads.aperture else MAX_NON_APERTURE_SPADS
    if len(spads.good_map) != SPAD_MAP_BYTES:
        raise ValueError(f"the good SPAD map is {SPAD_MAP_BYTES} bytes, got {len(spads.good_map)}")
    if spads.count > limit:
        raise ValueError(f"NVM asks for {spads.count} {kind} reference SPADs; at most {limit}")
    first, end = (FIRST_APERTURE_SPAD, SPADS) if spads.aperture else (0, FIRST_APERTURE_SPAD)
    working = [n for n in range(first, end) if spads.good_map[n // 8] >> (n % 8) & 1]
    if len(working) < spads.count:
        raise ValueError(
            f"NVM asks for {spads.count} {kind} reference SPADs; its map has {len(working)}"
        )
    enables = bytearray(SPAD_MAP_BYTES)
    for n in working[: spads.count]:
        enables[n // 8] |= 1 << (n % 8)
    return bytes(enables)

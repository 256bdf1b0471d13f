"""The sRGB curve's 8-bit decoder: its table gives the formula's values exactly."""

from __future__ import annotations

import numpy as np

from synthua_usd.model.srgb import decode_srgb8, encode_srgb8, to_linear


def test_decoding_8_bit_values_by_table_is_the_formula():
    values = np.random.default_rng(0).integers(0, 256, (7, 9, 3), dtype=np.uint8)
    decoded = decode_srgb8(values)
    assert decoded.dtype == np.float64 and decoded.shape == values.shape
    np.testing.assert_array_equal(decoded, to_linear(values / 255.0))
    np.testing.assert_array_equal(encode_srgb8(decode_srgb8(np.arange(256, dtype=np.uint8))),
                                  np.arange(256, dtype=np.uint8))
    np.testing.assert_array_equal(decode_srgb8(np.array([0.0, 255.0])), [0.0, 1.0])  # other dtypes: the formula

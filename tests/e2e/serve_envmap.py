"""test_serve.py's checks of environment maps (equirectangular views) on the main daemon: a
16-bit linear snapshot whose samples are luminance at the full scale its tEXt chunk gives
(against the daemon's own probe at the zenith and the horizon), the same view as 8-bit, a
stream of panoramas, and a view that is not 2:1 refused with the field named."""

import math
import struct

from serve_harness import (FIRST_FRAME_TIMEOUT, bad_input, check, check_binary_frame,
                           decode_png_full, info, short)

FULL_SCALE_KEY = "Luminance full scale cd/m2"
WIDTH, HEIGHT = 128, 64


def row_luminance(png, y, full_scale):
    """Mean luminance (Rec. 709 weights) of row y of a 16-bit RGB PNG, cd/m2."""
    row = png["rows"][y]
    samples = struct.unpack(f">{len(row) // 2}H", row)
    total = 0.0
    for i in range(0, len(samples), 3):
        r, g, b = samples[i:i + 3]
        total += 0.2126 * r + 0.7152 * g + 0.0722 * b
    return total / (len(samples) // 3) / 65535.0 * full_scale


async def probe_luminance(ctl, view_zenith_deg, sun_zenith_deg, altitude_km, tag):
    r = await ctl.request({"type": "probe", "id": tag, "quantity": "luminance",
                           "altitude_km": altitude_km, "view_zenith_deg": view_zenith_deg,
                           "view_azimuth_deg": 90, "sun_zenith_deg": sun_zenith_deg})
    rgb = r.get("luminance")
    if not check(f"envmap: probe {tag}", isinstance(rgb, list) and len(rgb) == 3, short(r)):
        return None
    return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]


async def t_envmap(d, ctl, viewer):
    before = (await ctl.get_state())["state"]
    clouds = before["clouds"]
    # A clear sky: the probe shades the sky without clouds.
    r = await ctl.request({"type": "set", "id": "env-clear", "patch": {
        "clouds": {"low": {"coverage": 0}, "high": {"coverage": 0}},
        "weather": {"map_source": "procedural", "autopilot": "off"}}})
    check("envmap: clear sky set", r.get("type") == "ack", short(r))
    state = (await ctl.get_state())["state"]
    sun_zenith = 90.0 - state["sun"]["elevation_deg"]
    altitude = state["camera"]["altitude_km"]

    r = await viewer.request({"type": "snapshot", "id": "env16", "view": {
        "width": WIDTH, "height": HEIGHT, "projection": "equirectangular", "format": "png16"}},
        FIRST_FRAME_TIMEOUT)
    binary = r.get("_binary")
    if check("envmap: png16 snapshot is a frame", r.get("type") == "frame"
             and isinstance(binary, bytes), short({k: v for k, v in r.items() if k != "_binary"})):
        check_binary_frame("envmap png16", r, binary, WIDTH, HEIGHT, fmt_expected=2)
        png = decode_png_full(binary[48:])
        full_scale = float(png["text"].get(FULL_SCALE_KEY, "nan"))
        check("envmap: full scale in tEXt", math.isfinite(full_scale) and full_scale > 0,
              short(png["text"]))
        check("envmap: gAMA is linear (100000)", png["gamma"] == 100000, str(png["gamma"]))
        with open(f"{d.scratch}/envmap16.png", "wb") as f:  # for review
            f.write(binary[48:])
        # Row 0 looks 90 - 180 * 0.5 / HEIGHT degrees up; the row just above the horizon
        # (HEIGHT / 2 - 1) at 90 * (1 / HEIGHT) degrees elevation, whatever the azimuth for
        # the zenith, and the mean over every azimuth is compared there against the probe
        # at 90 deg from the sun (the mean is near it within a few percent).
        zenith_row = row_luminance(png, 0, full_scale)
        probe = await probe_luminance(ctl, 180.0 * 0.5 / HEIGHT, sun_zenith, altitude, "env-z")
        if probe:
            ratio = zenith_row / probe
            info(f"envmap png16: full scale {full_scale:.6g} cd/m2; zenith row {zenith_row:.5g}, "
                 f"probe {probe:.5g} cd/m2 (ratio {ratio:.4f})")
            check("envmap: zenith row matches the probe within 2 %", abs(ratio - 1) < 0.02,
                  f"png16 {zenith_row:.5g} cd/m2, probe {probe:.5g} cd/m2, ratio {ratio:.4f}")
        horizon_row = row_luminance(png, HEIGHT // 2 - 1, full_scale)
        ground_row = row_luminance(png, HEIGHT - 1, full_scale)
        check("envmap: sky above the horizon brighter than the zenith and the nadir ground",
              horizon_row > zenith_row and horizon_row > ground_row,
              f"horizon {horizon_row:.5g}, zenith {zenith_row:.5g}, nadir {ground_row:.5g}")

    r = await viewer.request({"type": "snapshot", "id": "env8", "view": {
        "width": WIDTH, "height": HEIGHT, "projection": "equirectangular"}}, FIRST_FRAME_TIMEOUT)
    if check("envmap: png snapshot is a frame", r.get("type") == "frame", short(
            {k: v for k, v in r.items() if k != "_binary"})):
        check_binary_frame("envmap png", r, r.get("_binary"), WIDTH, HEIGHT)

    # A stream of 8-bit panoramas.
    r = await viewer.request({"type": "subscribe", "id": "env-sub", "view": {
        "width": 64, "height": 32, "fps": 5, "projection": "equirectangular"}})
    sub = r.get("subscription")
    if check("envmap: subscribed", r.get("type") == "subscribed"
             and r.get("view", {}).get("projection") == "equirectangular", short(r)):
        for k in range(2):
            m, binary = await viewer.wait_frame(lambda m: m.get("subscription") == sub,
                                                FIRST_FRAME_TIMEOUT)
            check_binary_frame(f"envmap stream frame {k}", m, binary, 64, 32)
        r = await viewer.request({"type": "unsubscribe", "id": "env-unsub", "subscription": sub})
        check("envmap: unsubscribed", r.get("type") == "ack", short(r))

    await bad_input("envmap: 3:2 panorama", viewer,
                    {"type": "snapshot", "id": "env-bad", "view": {
                        "width": 96, "height": 64, "projection": "equirectangular"}},
                    "inconsistent", "/view/width", "env-bad")
    await bad_input("envmap: unknown projection", viewer,
                    {"type": "subscribe", "id": "env-bad2", "view": {
                        "width": 96, "height": 48, "projection": "cubemap"}},
                    "bad_value", "/view/projection", "env-bad2")

    r = await ctl.request({"type": "set", "id": "env-restore", "patch": {
        "clouds": {"low": {"coverage": clouds["low"]["coverage"]},
                   "high": {"coverage": clouds["high"]["coverage"]}},
        "weather": {"map_source": before["weather"]["map_source"],
                    "autopilot": before["weather"]["autopilot"]}}})
    check("envmap: state restored", r.get("type") == "ack", short(r))

#!/usr/bin/python3
"""Prints tests/unit/ephemeris_reference.h: sun and moon positions from PyEphem (libastro), an
established ephemeris independent of skyd's, for tests/unit/test_ephemeris.c and tests/e2e/test_cli.sh.

    /usr/bin/python3 tests/tools/make_ephemeris_reference.py > tests/unit/ephemeris_reference.h

Needs Debian's python3-ephem (apt-get install python3-ephem) only when regenerating; the tests
read the committed header. The cases are drawn from a fixed seed, so a rerun with the same
PyEphem prints the same table.
"""
import calendar
import datetime
import math
import random

import ephem

SEED = 20260621
CASES = 96

# name, latitude (deg, north), longitude (deg, east), altitude (m)
SITES = [
    ("Greenwich", 51.4769, -0.0005, 46),
    ("NREL Golden", 39.742476, -105.1786, 1830),
    ("Sydney", -33.8688, 151.2093, 58),
    ("Tromso", 69.6492, 18.9553, 10),
    ("McMurdo", -77.8460, 166.6760, 10),
    ("Longyearbyen", 78.2232, 15.6267, 20),
    ("Quito", -0.1807, -78.4678, 2850),
    ("La Paz", -16.4897, -68.1193, 3000),
    ("Cape Town", -33.9249, 18.4241, 0),
    ("Tokyo", 35.6762, 139.6503, 40),
    ("Honolulu", 21.3069, -157.8583, 5),
    ("Reykjavik", 64.1466, -21.9426, 20),
    ("Ushuaia", -54.8019, -68.3030, 20),
    ("Anchorage", 61.2181, -149.9003, 30),
    ("Singapore", 1.3521, 103.8198, 15),
    ("Kathmandu", 27.7172, 85.3240, 1400),
    ("Alert", 82.5018, -62.3481, 30),
    ("Auckland", -36.8485, 174.7633, 20),
]

START = datetime.datetime(1900, 1, 1)
END = datetime.datetime(2100, 12, 31, 23, 59, 59)


def observer(site, when, pressure, temperature):
    o = ephem.Observer()
    o.lat = math.radians(site[1])  # floats are radians in PyEphem
    o.lon = math.radians(site[2])
    o.elevation = site[3]
    o.date = ephem.Date(when)  # a naive datetime is UTC
    o.pressure = pressure
    o.temp = temperature
    return o


def near_horizon(rng, site, when, body, pressure, temperature):
    """A time a few minutes around the body's rising or setting after `when`, or None."""
    o = observer(site, when, pressure, temperature)
    try:
        event = o.next_rising(body) if rng.random() < 0.5 else o.next_setting(body)
    except (ephem.AlwaysUpError, ephem.NeverUpError):
        return None
    return event.datetime() + datetime.timedelta(minutes=rng.uniform(-4.0, 30.0))


def position(site, when, body, pressure, temperature):
    o = observer(site, when, pressure, temperature)
    body.compute(o)
    return math.degrees(body.az) % 360.0, math.degrees(body.alt), body


def iso_text(rng, when):
    """The case's time as ISO 8601 text: UTC or a local offset, sometimes with fractions."""
    kind = rng.random()
    offset = datetime.timedelta(0)
    if kind > 0.6:
        offset = datetime.timedelta(minutes=rng.choice([-600, -420, -180, 60, 330, 345, 720]))
    local = when + offset
    text = local.strftime("%Y-%m-%dT%H:%M:%S")
    if when.microsecond:
        text += ".%03d" % (when.microsecond // 1000)
    if offset:
        minutes = int(offset.total_seconds() // 60)
        sign = "+" if minutes >= 0 else "-"
        text += "%s%02d:%02d" % (sign, abs(minutes) // 60, abs(minutes) % 60)
    else:
        text += "Z"
    return text


def make_case(rng, index):
    site = SITES[index % len(SITES)]
    span = (END - START).total_seconds()
    when = START + datetime.timedelta(seconds=int(rng.uniform(0, span)))
    # A barometric pressure for the site's altitude (ISA) and a varied temperature.
    pressure = round(1013.25 * (1.0 - 2.25577e-5 * site[3]) ** 5.25588, 1)
    temperature = round(rng.uniform(-25.0, 30.0), 1)
    # Every third case near sunrise or sunset, every fifth near moonrise or moonset, where
    # refraction matters most.
    special = None
    if index % 3 == 1:
        special = near_horizon(rng, site, when, ephem.Sun(), pressure, temperature)
    elif index % 5 == 2:
        special = near_horizon(rng, site, when, ephem.Moon(), pressure, temperature)
    if special is not None:
        when = special
    if rng.random() < 0.2:
        when = when.replace(microsecond=rng.randrange(1, 1000) * 1000)
    else:
        when = when.replace(microsecond=0)
    unix = calendar.timegm(when.timetuple()) + when.microsecond / 1e6

    sun_az, sun_el, _ = position(site, when, ephem.Sun(), 0.0, temperature)
    _, sun_el_refracted, _ = position(site, when, ephem.Sun(), pressure, temperature)
    moon_az, moon_el, moon = position(site, when, ephem.Moon(), 0.0, temperature)
    _, moon_el_refracted, _ = position(site, when, ephem.Moon(), pressure, temperature)
    fraction = moon.phase / 100.0
    distance_km = moon.earth_distance * ephem.meters_per_au / 1000.0
    return ('    { "%s", "%s", %.3f, %.6f, %.6f, %.1f, %.1f, %.1f,\n'
            '      %.6f, %.6f, %.6f, %.6f, %.6f, %.6f, %.6f, %.1f },'
            % (site[0], iso_text(rng, when), unix, site[1], site[2], site[3], pressure,
               temperature, sun_az, sun_el, sun_el_refracted, moon_az, moon_el,
               moon_el_refracted, fraction, distance_km))


def main():
    rng = random.Random(SEED)
    rows = [make_case(rng, i) for i in range(CASES)]
    print("""/* Reference positions of the sun and the moon for tests/unit/test_ephemeris.c and tests/e2e/test_cli.sh.
 * Generated by tests/tools/make_ephemeris_reference.py with PyEphem %s (libastro); do not edit,
 * regenerate. Topocentric apparent places; azimuth from north through east; elevations without
 * refraction (PyEphem pressure 0) and with it (at the case's pressure and temperature);
 * the moon's illuminated fraction (phase / 100) and distance from the site (earth_distance). */
#ifndef SKYD_TEST_EPHEMERIS_REFERENCE_H
#define SKYD_TEST_EPHEMERIS_REFERENCE_H

struct ephemeris_reference {
    const char *site, *time;
    double unix_seconds;
    double latitude_deg, longitude_deg, altitude_m, pressure_mbar, temperature_c;
    double sun_azimuth_deg, sun_elevation_deg, sun_elevation_refracted_deg;
    double moon_azimuth_deg, moon_elevation_deg, moon_elevation_refracted_deg;
    double moon_illuminated_fraction, moon_distance_km;
};

static const struct ephemeris_reference ephemeris_reference[] = {""" % ephem.__version__)
    print("\n".join(rows))
    print("""};

#endif""")


if __name__ == "__main__":
    main()

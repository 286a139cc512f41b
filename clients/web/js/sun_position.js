// Approximate sun position for a UTC time and a site, used to move the sun with the clock
// while clock.sky_bodies is "manual". NOAA Global Monitoring Division, "General Solar
// Position Calculations" (fractional year, equation of time, declination; about 0.1 degree).

const RAD = Math.PI / 180;

// Returns {elevationDeg, azimuthDeg} with the azimuth from north through east in [0, 360).
export function sunPosition(date, latitudeDeg, longitudeDeg) {
  const start = Date.UTC(date.getUTCFullYear(), 0, 1);
  const dayOfYear = Math.floor((date.getTime() - start) / 86400000) + 1;
  const hours = date.getUTCHours() + date.getUTCMinutes() / 60 + date.getUTCSeconds() / 3600;
  const leap = new Date(Date.UTC(date.getUTCFullYear(), 1, 29)).getUTCMonth() === 1;
  const gamma = (2 * Math.PI / (leap ? 366 : 365)) * (dayOfYear - 1 + (hours - 12) / 24);
  // NOAA: equation of time (minutes)
  const eqTime = 229.18 * (0.000075 + 0.001868 * Math.cos(gamma) - 0.032077 * Math.sin(gamma)
    - 0.014615 * Math.cos(2 * gamma) - 0.040849 * Math.sin(2 * gamma));
  // NOAA: solar declination (radians)
  const decl = 0.006918 - 0.399912 * Math.cos(gamma) + 0.070257 * Math.sin(gamma)
    - 0.006758 * Math.cos(2 * gamma) + 0.000907 * Math.sin(2 * gamma)
    - 0.002697 * Math.cos(3 * gamma) + 0.00148 * Math.sin(3 * gamma);
  // NOAA: true solar time (minutes) and hour angle
  const trueSolarMinutes = hours * 60 + eqTime + 4 * longitudeDeg;
  const hourAngle = (trueSolarMinutes / 4 - 180) * RAD;
  const lat = latitudeDeg * RAD;
  const cosZenith = Math.sin(lat) * Math.sin(decl)
    + Math.cos(lat) * Math.cos(decl) * Math.cos(hourAngle);
  const zenith = Math.acos(Math.min(1, Math.max(-1, cosZenith)));
  // Azimuth from north through east, from the east and north components of the sun direction.
  const east = -Math.cos(decl) * Math.sin(hourAngle);
  const north = Math.sin(decl) * Math.cos(lat)
    - Math.cos(decl) * Math.cos(hourAngle) * Math.sin(lat);
  let azimuth = Math.atan2(east, north) / RAD;
  if (azimuth < 0) azimuth += 360;
  return { elevationDeg: 90 - zenith / RAD, azimuthDeg: azimuth };
}

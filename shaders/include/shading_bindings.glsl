// Bindings 0-7, common to every pass that shades view directions (composite, probe, meter).
layout(std140, binding = 0) uniform AtmosphereBlock { sky_atmosphere_uniforms atmo; };
layout(std140, binding = 1) uniform FrameBlock { sky_frame_uniforms frame; };
layout(binding = 2) uniform sampler2D transmittance_lut;
layout(binding = 3) uniform sampler2D multiscattering_lut;
layout(binding = 4) uniform sampler2D skyview_lut;
layout(binding = 5) uniform sampler2D irradiance_lut;
layout(binding = 6) uniform sampler3D ap_inscatter_lut;
layout(binding = 7) uniform sampler3D ap_transmittance_lut;

#define SKY_HAS_TRANSMITTANCE_LUT
#define SKY_HAS_MULTISCATTERING_LUT

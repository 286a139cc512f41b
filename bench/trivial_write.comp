#version 450
// The bench's yardstick: the cheapest full-image compute pass, one constant-ish colour
// written per pixel to an RGBA8 storage image.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, rgba8) uniform writeonly image2D image_out;

void main()
{
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(image_out);
    if (any(greaterThanEqual(px, size)))
        return;
    imageStore(image_out, px, vec4(vec2(px) / vec2(size), 0.5, 1.0));
}

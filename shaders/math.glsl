// Shared constants.
const float KIT_PI = 3.14159265358979;
// Rec. 709 luminance weights for linear RGB.
const vec3 KIT_LUMINANCE = vec3(0.2126, 0.7152, 0.0722);

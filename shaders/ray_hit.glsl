// The payload of the rays that ask which object they hit first
// (shadow_rays.rgen occludedBySelf): the closest hit's object (its
// instance's custom index, the object's index) and distance, or kNoObject
// where the ray leaves the scene.
const uint kNoObject = 0xFFFFFFFFu;
struct ObjectHit {
  uint object;
  float t;
};

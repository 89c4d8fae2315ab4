#include "render/transform.h"

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

namespace rlpbrt {

Mat4 translateMatrix(const Vec3& d) { return glm::translate(Mat4(1.f), d); }
Mat4 scaleMatrix(const Vec3& s) { return glm::scale(Mat4(1.f), s); }

Mat4 rotateMatrix(float deg, const Vec3& axis) {
    float len = glm::length(axis);
    if (len == 0.f) return Mat4(1.f);
    return glm::rotate(Mat4(1.f), radians(deg), axis / len);
}

bool lookAtMatrix(const Vec3& eye, const Vec3& look, const Vec3& up, Mat4* m) {
    *m = Mat4(1.f);
    Vec3 dir = look - eye;
    if (glm::length(dir) == 0.f || glm::length(up) == 0.f) return false;
    dir = glm::normalize(dir);
    Vec3 right = glm::cross(glm::normalize(up), dir);
    if (glm::length(right) < 1e-6f) return false;
    right = glm::normalize(right);
    Vec3 newUp = glm::cross(dir, right);
    Mat4 worldFromCamera(Vec4(right, 0.f), Vec4(newUp, 0.f), Vec4(dir, 0.f), Vec4(eye, 1.f));
    *m = glm::inverse(worldFromCamera);
    return true;
}

Mat4 matrixFromPbrt(const std::array<float, 16>& v) { return glm::make_mat4(v.data()); }

}  // namespace rlpbrt

// glTF binary data: component types, buffer views and accessors, every range checked before use.

#include "scene/gltf_loader_internal.h"

namespace bdptref {
namespace gltfload {

std::string fmt(double v) {
    std::ostringstream os;
    os.precision(9);
    os << v;
    return os.str();
}

std::string lower(std::string s) {
    for (char& ch : s) ch = char(std::tolower(static_cast<unsigned char>(ch)));
    return s;
}

bool endsWith(const std::string& s, const std::string& suffix) {
    return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

bool mulOverflows(size_t a, size_t b, size_t* out) {
    if (a != 0 && b > std::numeric_limits<size_t>::max() / a) return true;
    *out = a * b;
    return false;
}
bool addOverflows(size_t a, size_t b, size_t* out) {
    if (b > std::numeric_limits<size_t>::max() - a) return true;
    *out = a + b;
    return false;
}

size_t componentSize(int ct) {
    switch (ct) {
        case TINYGLTF_COMPONENT_TYPE_BYTE:
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
        case TINYGLTF_COMPONENT_TYPE_SHORT:
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
        case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
        default: return 0;  // INT and DOUBLE are not valid glTF 2.0 accessor component types
    }
}

const char* componentTypeName(int ct) {
    switch (ct) {
        case TINYGLTF_COMPONENT_TYPE_BYTE: return "BYTE";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return "UNSIGNED_BYTE";
        case TINYGLTF_COMPONENT_TYPE_SHORT: return "SHORT";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return "UNSIGNED_SHORT";
        case TINYGLTF_COMPONENT_TYPE_INT: return "INT";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return "UNSIGNED_INT";
        case TINYGLTF_COMPONENT_TYPE_FLOAT: return "FLOAT";
        case TINYGLTF_COMPONENT_TYPE_DOUBLE: return "DOUBLE";
        default: return "unknown";
    }
}

int typeComponents(int type) {
    switch (type) {
        case TINYGLTF_TYPE_SCALAR: return 1;
        case TINYGLTF_TYPE_VEC2: return 2;
        case TINYGLTF_TYPE_VEC3: return 3;
        case TINYGLTF_TYPE_VEC4: return 4;
        case TINYGLTF_TYPE_MAT2: return 4;
        case TINYGLTF_TYPE_MAT3: return 9;
        case TINYGLTF_TYPE_MAT4: return 16;
        default: return 0;
    }
}

const char* typeName(int type) {
    switch (type) {
        case TINYGLTF_TYPE_SCALAR: return "SCALAR";
        case TINYGLTF_TYPE_VEC2: return "VEC2";
        case TINYGLTF_TYPE_VEC3: return "VEC3";
        case TINYGLTF_TYPE_VEC4: return "VEC4";
        case TINYGLTF_TYPE_MAT2: return "MAT2";
        case TINYGLTF_TYPE_MAT3: return "MAT3";
        case TINYGLTF_TYPE_MAT4: return "MAT4";
        default: return "unknown";
    }
}

const char* modeName(int mode) {
    switch (mode) {
        case TINYGLTF_MODE_POINTS: return "POINTS";
        case TINYGLTF_MODE_LINE: return "LINES";
        case TINYGLTF_MODE_LINE_LOOP: return "LINE_LOOP";
        case TINYGLTF_MODE_LINE_STRIP: return "LINE_STRIP";
        case TINYGLTF_MODE_TRIANGLES: return "TRIANGLES";
        case TINYGLTF_MODE_TRIANGLE_STRIP: return "TRIANGLE_STRIP";
        case TINYGLTF_MODE_TRIANGLE_FAN: return "TRIANGLE_FAN";
        default: return "unknown";
    }
}

// One component, decoded per the glTF spec (normalized integers map to [0,1] or [-1,1]).
double readComponent(const unsigned char* p, int ct, bool normalized) {
    switch (ct) {
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
            const uint8_t v = *p;
            return normalized ? double(v) / 255.0 : double(v);
        }
        case TINYGLTF_COMPONENT_TYPE_BYTE: {
            int8_t v;
            std::memcpy(&v, p, 1);
            return normalized ? std::max(double(v) / 127.0, -1.0) : double(v);
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
            uint16_t v;
            std::memcpy(&v, p, 2);
            return normalized ? double(v) / 65535.0 : double(v);
        }
        case TINYGLTF_COMPONENT_TYPE_SHORT: {
            int16_t v;
            std::memcpy(&v, p, 2);
            return normalized ? std::max(double(v) / 32767.0, -1.0) : double(v);
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
            uint32_t v;
            std::memcpy(&v, p, 4);
            return double(v);
        }
        case TINYGLTF_COMPONENT_TYPE_FLOAT: {
            float v;
            std::memcpy(&v, p, 4);
            return double(v);
        }
        default: return 0.0;
    }
}


// ----- accessors

const unsigned char* Loader::viewBytes(int viewIndex, const std::string& who, size_t* length, size_t* stride) const {
    if (viewIndex < 0 || size_t(viewIndex) >= model_.bufferViews.size())
        fail(who + ": bufferView " + std::to_string(viewIndex) + " does not exist (the file has " +
             std::to_string(model_.bufferViews.size()) + ")");
    const tinygltf::BufferView& bv = model_.bufferViews[size_t(viewIndex)];
    const std::string vname = "bufferView " + std::to_string(viewIndex);
    if (bv.buffer < 0 || size_t(bv.buffer) >= model_.buffers.size())
        fail(who + ": " + vname + " refers to buffer " + std::to_string(bv.buffer) + ", which does not exist");
    const tinygltf::Buffer& buf = model_.buffers[size_t(bv.buffer)];
    if (bv.byteLength == 0) fail(who + ": " + vname + " has byteLength 0");
    size_t end = 0;
    if (addOverflows(bv.byteOffset, bv.byteLength, &end) || end > buf.data.size())
        fail(who + ": " + vname + " extends past the end of buffer " + std::to_string(bv.buffer) + " (needs " +
             (end ? std::to_string(end) : std::string("more than 2^64")) + " bytes, has " + std::to_string(buf.data.size()) + ")");
    *length = bv.byteLength;
    *stride = bv.byteStride;
    return buf.data.data() + bv.byteOffset;
}

const tinygltf::Accessor& Loader::accessor(int index, const std::string& who) const {
    if (index < 0 || size_t(index) >= model_.accessors.size())
        fail(who + " does not exist (the file has " + std::to_string(model_.accessors.size()) + " accessors)");
    return model_.accessors[size_t(index)];
}

DecodedAccessor Loader::decode(int index, const std::string& who, const std::vector<int>& types,
                               const std::vector<AccessorFormat>& formats) const {
    const tinygltf::Accessor& acc = accessor(index, who);

    bool typeOk = false;
    for (int t : types) typeOk = typeOk || t == acc.type;
    if (!typeOk) {
        std::string expected;
        for (int t : types) expected += (expected.empty() ? "" : " or ") + std::string(typeName(t));
        fail(who + " has type " + typeName(acc.type) + "; expected " + expected);
    }
    bool formatOk = false;
    for (const AccessorFormat& f : formats) formatOk = formatOk || (f.componentType == acc.componentType && f.normalized == acc.normalized);
    if (!formatOk) {
        std::string expected;
        for (const AccessorFormat& f : formats)
            expected += (expected.empty() ? "" : " or ") + std::string(componentTypeName(f.componentType)) +
                        (f.normalized ? " normalized" : "");
        fail(who + " has componentType " + componentTypeName(acc.componentType) + (acc.normalized ? " normalized" : "") +
             "; expected " + expected);
    }
    const int nc = typeComponents(acc.type);
    const size_t cs = componentSize(acc.componentType);
    const size_t elementSize = cs * size_t(nc);
    if (acc.count == 0) fail(who + " has count 0");
    // Every vertex or index ends up in uint32 indices; beyond that the file cannot be represented.
    if (acc.count > size_t(std::numeric_limits<uint32_t>::max()))
        fail(who + " has count " + std::to_string(acc.count) + ", more than this renderer supports (2^32 - 1)");

    DecodedAccessor out;
    out.count = acc.count;
    out.components = nc;

    if (acc.bufferView >= 0) {
        size_t viewLength = 0, viewStride = 0;
        const unsigned char* base = viewBytes(acc.bufferView, who, &viewLength, &viewStride);
        const size_t stride = viewStride ? viewStride : elementSize;
        if (stride < elementSize)
            fail(who + ": bufferView " + std::to_string(acc.bufferView) + " has byteStride " + std::to_string(viewStride) +
                 ", smaller than the element size " + std::to_string(elementSize) + " bytes");
        size_t needed = 0, span = 0;
        if (mulOverflows(stride, acc.count - 1, &span) || addOverflows(span, elementSize, &span) ||
            addOverflows(span, acc.byteOffset, &needed) || needed > viewLength)
            fail(who + " reads past the end of bufferView " + std::to_string(acc.bufferView) + " (needs " +
                 (needed ? std::to_string(needed) : std::string("more than 2^64")) + " bytes, has " +
                 std::to_string(viewLength) + ")");
        out.values.resize(acc.count * size_t(nc));
        const unsigned char* p = base + acc.byteOffset;
        for (size_t i = 0; i < acc.count; ++i, p += stride)
            for (int c = 0; c < nc; ++c)
                out.values[i * size_t(nc) + size_t(c)] = readComponent(p + size_t(c) * cs, acc.componentType, acc.normalized);
    } else {
        if (!acc.sparse.isSparse) fail(who + " has neither a bufferView nor sparse data");
        out.values.assign(acc.count * size_t(nc), 0.0);  // spec: zeros, then the sparse substitution
    }

    if (acc.sparse.isSparse) {
        const std::string sw = who + " sparse";
        const auto& sp = acc.sparse;
        if (sp.count <= 0 || size_t(sp.count) > acc.count)
            fail(sw + ".count " + std::to_string(sp.count) + " is not in [1, " + std::to_string(acc.count) + "]");
        const int ict = sp.indices.componentType;
        if (ict != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && ict != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
            ict != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
            fail(sw + ".indices has componentType " + componentTypeName(ict) + "; expected an unsigned integer type");
        if (sp.indices.byteOffset < 0 || sp.values.byteOffset < 0) fail(sw + " has a negative byteOffset");
        const size_t n = size_t(sp.count);
        size_t len = 0, vstride = 0, need = 0;
        const unsigned char* ib = viewBytes(sp.indices.bufferView, sw + ".indices", &len, &vstride);
        const size_t ics = componentSize(ict);
        if (mulOverflows(n, ics, &need) || addOverflows(need, size_t(sp.indices.byteOffset), &need) || need > len)
            fail(sw + ".indices reads past the end of bufferView " + std::to_string(sp.indices.bufferView) + " (needs " +
                 std::to_string(need) + " bytes, has " + std::to_string(len) + ")");
        std::vector<size_t> idx(n);
        for (size_t i = 0; i < n; ++i) {
            const double d = readComponent(ib + size_t(sp.indices.byteOffset) + i * ics, ict, false);
            idx[i] = size_t(d);
            if (idx[i] >= acc.count)
                fail(sw + ".indices[" + std::to_string(i) + "] = " + std::to_string(idx[i]) + " is out of range (count " +
                     std::to_string(acc.count) + ")");
            if (i > 0 && idx[i] <= idx[i - 1]) fail(sw + ".indices are not strictly increasing at position " + std::to_string(i));
        }
        const unsigned char* vb = viewBytes(sp.values.bufferView, sw + ".values", &len, &vstride);
        if (mulOverflows(n, elementSize, &need) || addOverflows(need, size_t(sp.values.byteOffset), &need) || need > len)
            fail(sw + ".values reads past the end of bufferView " + std::to_string(sp.values.bufferView) + " (needs " +
                 std::to_string(need) + " bytes, has " + std::to_string(len) + ")");
        for (size_t i = 0; i < n; ++i)
            for (int c = 0; c < nc; ++c)
                out.values[idx[i] * size_t(nc) + size_t(c)] = readComponent(
                    vb + size_t(sp.values.byteOffset) + i * elementSize + size_t(c) * cs, acc.componentType, acc.normalized);
    }
    return out;
}


}  // namespace gltfload
}  // namespace bdptref

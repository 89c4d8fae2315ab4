#include "render/materials.h"

#include <algorithm>

#include "render/bssrdf.h"
#include "render/fourier_bsdf.h"
#include "render/hair.h"

namespace rlpbrt {

Material::~Material() = default;

TextureContext textureContext(const SurfaceInteraction& si) {
    TextureContext tc;
    tc.p = si.p;
    tc.dpdx = tc.dpdy = Vec3(0.f);
    tc.n = si.ns;
    tc.uv = si.uv;
    return tc;
}

namespace {

using FTex = std::shared_ptr<FloatTexture>;
using STex = std::shared_ptr<SpectrumTexture>;

Spectrum clampZero(const Spectrum& s) { return glm::max(s, Spectrum(0.f)); }

// Shared by every material type: the bump map and the shading frame.
class SurfaceMaterial : public Material {
public:
    explicit SurfaceMaterial(FTex bump) : bump_(std::move(bump)) {}

protected:
    // Initializes the BSDF's frame at si (bump-mapped when a bump map is present).
    void initFrame(const SurfaceInteraction& si, const TextureContext& tc, BSDF* bsdf,
                   float eta = 1.f) const {
        Vec3 ns = si.ns, dpdu = si.dpdu;
        if (bump_) {
            BumpInput in;
            in.p = si.p;
            in.n = si.ng;
            in.ns = si.ns;
            in.dpdu = si.dpdu;
            in.dpdv = si.dpdv;
            in.dndu = si.dndu;
            in.dndv = si.dndv;
            in.uv = si.uv;
            Vec3 dpdv;
            bump(*bump_, in, &dpdu, &dpdv, &ns);
            if (!isFinite(ns) || glm::dot(ns, ns) == 0.f) {
                ns = si.ns;
                dpdu = si.dpdu;
            }
        }
        Vec3 tangent = glm::length(si.shadingTangent) > 0.f ? si.shadingTangent : dpdu;
        bsdf->init(si.ng, ns, tangent, eta);
        (void)tc;
    }

    FTex bump_;
};

class MatteMaterial : public SurfaceMaterial {
public:
    MatteMaterial(STex kd, FTex sigma, FTex bump)
        : SurfaceMaterial(std::move(bump)), kd_(std::move(kd)), sigma_(std::move(sigma)) {}
    void computeBSDF(const SurfaceInteraction& si, float, BSDF* bsdf) const override {
        TextureContext tc = textureContext(si);
        initFrame(si, tc, bsdf);
        buildMatte(*bsdf, clampZero(kd_->evaluate(tc)), clamp(sigma_->evaluate(tc), 0.f, 90.f));
    }

private:
    STex kd_;
    FTex sigma_;
};

class PlasticMaterial : public SurfaceMaterial {
public:
    PlasticMaterial(STex kd, STex ks, FTex rough, bool remap, FTex bump)
        : SurfaceMaterial(std::move(bump)), kd_(std::move(kd)), ks_(std::move(ks)),
          rough_(std::move(rough)), remap_(remap) {}
    void computeBSDF(const SurfaceInteraction& si, float, BSDF* bsdf) const override {
        TextureContext tc = textureContext(si);
        initFrame(si, tc, bsdf);
        buildPlastic(*bsdf, clampZero(kd_->evaluate(tc)), clampZero(ks_->evaluate(tc)),
                     rough_->evaluate(tc), remap_);
    }

private:
    STex kd_, ks_;
    FTex rough_;
    bool remap_;
};

class MetalMaterial : public SurfaceMaterial {
public:
    MetalMaterial(STex eta, STex k, FTex u, FTex v, bool remap, FTex bump)
        : SurfaceMaterial(std::move(bump)), eta_(std::move(eta)), k_(std::move(k)),
          u_(std::move(u)), v_(std::move(v)), remap_(remap) {}
    void computeBSDF(const SurfaceInteraction& si, float, BSDF* bsdf) const override {
        TextureContext tc = textureContext(si);
        initFrame(si, tc, bsdf);
        buildMetal(*bsdf, eta_->evaluate(tc), k_->evaluate(tc), u_->evaluate(tc),
                   v_->evaluate(tc), remap_);
    }

private:
    STex eta_, k_;
    FTex u_, v_;
    bool remap_;
};

class GlassMaterial : public SurfaceMaterial {
public:
    GlassMaterial(STex kr, STex kt, FTex eta, FTex u, FTex v, bool remap, FTex bump)
        : SurfaceMaterial(std::move(bump)), kr_(std::move(kr)), kt_(std::move(kt)),
          eta_(std::move(eta)), u_(std::move(u)), v_(std::move(v)), remap_(remap) {}
    void computeBSDF(const SurfaceInteraction& si, float, BSDF* bsdf) const override {
        TextureContext tc = textureContext(si);
        float eta = eta_->evaluate(tc);
        initFrame(si, tc, bsdf, eta);
        buildGlass(*bsdf, clampZero(kr_->evaluate(tc)), clampZero(kt_->evaluate(tc)), eta,
                   u_->evaluate(tc), v_->evaluate(tc), remap_);
    }

private:
    STex kr_, kt_;
    FTex eta_, u_, v_;
    bool remap_;
};

class MirrorMaterial : public SurfaceMaterial {
public:
    MirrorMaterial(STex kr, FTex bump) : SurfaceMaterial(std::move(bump)), kr_(std::move(kr)) {}
    void computeBSDF(const SurfaceInteraction& si, float, BSDF* bsdf) const override {
        TextureContext tc = textureContext(si);
        initFrame(si, tc, bsdf);
        buildMirror(*bsdf, clampZero(kr_->evaluate(tc)));
    }

private:
    STex kr_;
};

class UberMaterial : public SurfaceMaterial {
public:
    UberMaterial(STex kd, STex ks, STex kr, STex kt, FTex u, FTex v, STex opacity, FTex eta,
                 bool remap, FTex bump)
        : SurfaceMaterial(std::move(bump)), kd_(std::move(kd)), ks_(std::move(ks)),
          kr_(std::move(kr)), kt_(std::move(kt)), u_(std::move(u)), v_(std::move(v)),
          opacity_(std::move(opacity)), eta_(std::move(eta)), remap_(remap) {}
    void computeBSDF(const SurfaceInteraction& si, float, BSDF* bsdf) const override {
        TextureContext tc = textureContext(si);
        float eta = eta_->evaluate(tc);
        Spectrum op = glm::clamp(opacity_->evaluate(tc), Spectrum(0.f), Spectrum(1.f));
        initFrame(si, tc, bsdf, isBlack(Spectrum(1.f) - op) ? eta : 1.f);
        buildUber(*bsdf, clampZero(kd_->evaluate(tc)), clampZero(ks_->evaluate(tc)),
                  clampZero(kr_->evaluate(tc)), clampZero(kt_->evaluate(tc)), u_->evaluate(tc),
                  v_->evaluate(tc), op, eta, remap_);
    }

private:
    STex kd_, ks_, kr_, kt_;
    FTex u_, v_;
    STex opacity_;
    FTex eta_;
    bool remap_;
};

class SubstrateMaterial : public SurfaceMaterial {
public:
    SubstrateMaterial(STex kd, STex ks, FTex u, FTex v, bool remap, FTex bump)
        : SurfaceMaterial(std::move(bump)), kd_(std::move(kd)), ks_(std::move(ks)),
          u_(std::move(u)), v_(std::move(v)), remap_(remap) {}
    void computeBSDF(const SurfaceInteraction& si, float, BSDF* bsdf) const override {
        TextureContext tc = textureContext(si);
        initFrame(si, tc, bsdf);
        buildSubstrate(*bsdf, clampZero(kd_->evaluate(tc)), clampZero(ks_->evaluate(tc)),
                       u_->evaluate(tc), v_->evaluate(tc), remap_);
    }

private:
    STex kd_, ks_;
    FTex u_, v_;
    bool remap_;
};

class TranslucentMaterial : public SurfaceMaterial {
public:
    TranslucentMaterial(STex kd, STex ks, STex reflect, STex transmit, FTex rough, bool remap,
                        FTex bump)
        : SurfaceMaterial(std::move(bump)), kd_(std::move(kd)), ks_(std::move(ks)),
          reflect_(std::move(reflect)), transmit_(std::move(transmit)),
          rough_(std::move(rough)), remap_(remap) {}
    void computeBSDF(const SurfaceInteraction& si, float, BSDF* bsdf) const override {
        TextureContext tc = textureContext(si);
        initFrame(si, tc, bsdf, 1.5f);
        buildTranslucent(*bsdf, clampZero(kd_->evaluate(tc)), clampZero(ks_->evaluate(tc)),
                         glm::clamp(reflect_->evaluate(tc), Spectrum(0.f), Spectrum(1.f)),
                         glm::clamp(transmit_->evaluate(tc), Spectrum(0.f), Spectrum(1.f)),
                         rough_->evaluate(tc), remap_);
    }

private:
    STex kd_, ks_, reflect_, transmit_;
    FTex rough_;
    bool remap_;
};

// pbrt-v3's DisneyMaterial (buildDisney has the lobes).
class DisneyMaterial : public SurfaceMaterial {
public:
    struct Textures {
        STex color, scatterDistance;
        FTex metallic, eta, roughness, specularTint, anisotropic, sheen, sheenTint, clearcoat,
            clearcoatGloss, specTrans, flatness, diffTrans;
        bool thin = false;
    };
    DisneyMaterial(Textures t, FTex bump) : SurfaceMaterial(std::move(bump)), t_(std::move(t)) {}
    void computeBSDF(const SurfaceInteraction& si, float, BSDF* bsdf) const override {
        TextureContext tc = textureContext(si);
        initFrame(si, tc, bsdf);
        DisneyParams p;
        p.color = t_.color->evaluate(tc);
        p.metallic = t_.metallic->evaluate(tc);
        p.eta = t_.eta->evaluate(tc);
        p.roughness = t_.roughness->evaluate(tc);
        p.specularTint = t_.specularTint->evaluate(tc);
        p.anisotropic = t_.anisotropic->evaluate(tc);
        p.sheen = t_.sheen->evaluate(tc);
        p.sheenTint = t_.sheenTint->evaluate(tc);
        p.clearcoat = t_.clearcoat->evaluate(tc);
        p.clearcoatGloss = t_.clearcoatGloss->evaluate(tc);
        p.specTrans = t_.specTrans->evaluate(tc);
        p.thin = t_.thin;
        if (p.thin) p.flatness = t_.flatness->evaluate(tc);
        p.diffTrans = t_.diffTrans->evaluate(tc);
        if (!p.thin) p.scatterDistance = clampZero(t_.scatterDistance->evaluate(tc));
        buildDisney(*bsdf, p);
    }

private:
    Textures t_;
};

// pbrt-v3's SubsurfaceMaterial and KdSubsurfaceMaterial: a dielectric boundary (smooth or
// rough, as glass) over a TabulatedBSSRDF of the photon beam diffusion table for (g, eta).
// Coefficients: sigma_a and sigma_s textures (subsurface), or a diffuse reflectance and mean
// free path inverted with the table (kdsubsurface; subsurface with "reflectance"); times
// scale.
class SubsurfaceMaterial : public SurfaceMaterial {
public:
    struct Textures {
        STex kr, kt, sigmaA, sigmaS, reflectance, mfp;  // reflectance set: the Kd/mfp form
        FTex u, v;
        float scale = 1.f, eta = 1.33f, g = 0.f;
        bool remap = true;
    };
    SubsurfaceMaterial(Textures t, FTex bump)
        : SurfaceMaterial(std::move(bump)), t_(std::move(t)),
          table_(beamDiffusionTable(t_.g, t_.eta)) {}
    void computeBSDF(const SurfaceInteraction& si, float, BSDF* bsdf) const override {
        TextureContext tc = textureContext(si);
        initFrame(si, tc, bsdf, t_.eta);
        buildGlass(*bsdf, clampZero(t_.kr->evaluate(tc)), clampZero(t_.kt->evaluate(tc)), t_.eta,
                   t_.u->evaluate(tc), t_.v->evaluate(tc), t_.remap);
        Spectrum sa, ss;
        if (t_.reflectance) {
            const Spectrum mfp = t_.scale * t_.mfp->evaluate(tc);
            const Spectrum kd = glm::clamp(t_.reflectance->evaluate(tc), Spectrum(0.f),
                                           Spectrum(1.f));
            subsurfaceFromDiffuse(*table_, kd, mfp, &sa, &ss);
        } else {
            sa = t_.scale * clampZero(t_.sigmaA->evaluate(tc));
            ss = t_.scale * clampZero(t_.sigmaS->evaluate(tc));
        }
        bsdf->setSubsurface(SeparableBSSRDF::tabulated(table_.get(), sa, ss, t_.eta));
    }

private:
    Textures t_;
    std::shared_ptr<const BSSRDFTable> table_;  // shared by the materials of the same g, eta
};

// pbrt-v3's FourierMaterial: one tabulated lobe (none, a black surface, if the table could not
// be read).
class FourierMaterial : public SurfaceMaterial {
public:
    FourierMaterial(std::shared_ptr<const FourierTable> table, FTex bump)
        : SurfaceMaterial(std::move(bump)), table_(std::move(table)) {}
    void computeBSDF(const SurfaceInteraction& si, float, BSDF* bsdf) const override {
        initFrame(si, textureContext(si), bsdf);
        bsdf->clear();
        if (table_) bsdf->add(FourierBSDF(table_.get(), TransportMode::Radiance));
    }

private:
    std::shared_ptr<const FourierTable> table_;
};

// pbrt-v3's mix weights m1 by `amount` and m2 by 1 - amount; here one of them is chosen per
// shading point with those probabilities (the same expectation). A coloured amount uses its
// average as the probability.
class MixMaterial : public Material {
public:
    MixMaterial(const Material* m1, const Material* m2, STex amount)
        : m1_(m1), m2_(m2), amount_(std::move(amount)) {}
    void computeBSDF(const SurfaceInteraction& si, float u, BSDF* bsdf) const override {
        Spectrum a = glm::clamp(amount_->evaluate(textureContext(si)), Spectrum(0.f),
                                Spectrum(1.f));
        float p = (a.x + a.y + a.z) / 3.f;
        const Material* m = u < p ? m1_ : m2_;
        // Reuse u for the chosen part, rescaled to [0,1).
        float u2 = u < p ? u / p : (u - p) / (1.f - p);
        u2 = std::min(u2, OneMinusEpsilon);
        if (m) {
            m->computeBSDF(si, u2, bsdf);
        } else {
            bsdf->init(si.ng, si.ns, si.dpdu);
            bsdf->clear();
        }
    }

private:
    const Material *m1_, *m2_;
    STex amount_;
};

// Copper, pbrt-v3's default eta and k for "metal", as RGB.
const Spectrum kCopperEta(0.200438f, 0.924033f, 1.10221f);
const Spectrum kCopperK(3.91295f, 2.45285f, 2.14219f);

}  // namespace

std::unique_ptr<Material> createMaterial(const MaterialEntity& e, TextureResolver& tex,
                                         const std::vector<const Material*>& materials,
                                         const std::vector<std::string>& names,
                                         Diagnostics& diag, bool* ok) {
    *ok = true;
    const ParamList& p = e.params;
    if (e.interfaceOnly()) {
        p.reportUnused("an interface material");
        return nullptr;
    }
    auto bump = p.has("bumpmap") ? tex.floatTex(p, "bumpmap", 0.f) : nullptr;
    bool remap = p.getBool("remaproughness", true);
    std::unique_ptr<Material> m;
    const std::string& t = e.type;
    if (t == "matte") {
        m = std::make_unique<MatteMaterial>(tex.spectrumTex(p, "Kd", Spectrum(0.5f)),
                                            tex.floatTex(p, "sigma", 0.f), bump);
    } else if (t == "plastic") {
        m = std::make_unique<PlasticMaterial>(tex.spectrumTex(p, "Kd", Spectrum(0.25f)),
                                              tex.spectrumTex(p, "Ks", Spectrum(0.25f)),
                                              tex.floatTex(p, "roughness", 0.1f), remap, bump);
    } else if (t == "metal") {
        auto rough = tex.floatTex(p, "roughness", 0.01f);
        auto u = p.has("uroughness") ? tex.floatTex(p, "uroughness", 0.f) : rough;
        auto v = p.has("vroughness") ? tex.floatTex(p, "vroughness", 0.f) : rough;
        m = std::make_unique<MetalMaterial>(tex.spectrumTex(p, "eta", kCopperEta),
                                            tex.spectrumTex(p, "k", kCopperK), u, v, remap,
                                            bump);
    } else if (t == "glass") {
        auto eta = p.has("eta") ? tex.floatTex(p, "eta", 1.5f) : tex.floatTex(p, "index", 1.5f);
        m = std::make_unique<GlassMaterial>(
            tex.spectrumTex(p, "Kr", Spectrum(1.f)), tex.spectrumTex(p, "Kt", Spectrum(1.f)), eta,
            tex.floatTex(p, "uroughness", 0.f), tex.floatTex(p, "vroughness", 0.f), remap, bump);
    } else if (t == "mirror") {
        m = std::make_unique<MirrorMaterial>(tex.spectrumTex(p, "Kr", Spectrum(0.9f)), bump);
    } else if (t == "uber") {
        auto rough = tex.floatTex(p, "roughness", 0.1f);
        auto u = p.has("uroughness") ? tex.floatTex(p, "uroughness", 0.f) : rough;
        auto v = p.has("vroughness") ? tex.floatTex(p, "vroughness", 0.f) : rough;
        auto eta = p.has("eta") ? tex.floatTex(p, "eta", 1.5f) : tex.floatTex(p, "index", 1.5f);
        m = std::make_unique<UberMaterial>(
            tex.spectrumTex(p, "Kd", Spectrum(0.25f)), tex.spectrumTex(p, "Ks", Spectrum(0.25f)),
            tex.spectrumTex(p, "Kr", Spectrum(0.f)), tex.spectrumTex(p, "Kt", Spectrum(0.f)), u,
            v, tex.spectrumTex(p, "opacity", Spectrum(1.f)), eta, remap, bump);
    } else if (t == "substrate") {
        m = std::make_unique<SubstrateMaterial>(
            tex.spectrumTex(p, "Kd", Spectrum(0.5f)), tex.spectrumTex(p, "Ks", Spectrum(0.5f)),
            tex.floatTex(p, "uroughness", 0.1f), tex.floatTex(p, "vroughness", 0.1f), remap,
            bump);
    } else if (t == "translucent") {
        m = std::make_unique<TranslucentMaterial>(
            tex.spectrumTex(p, "Kd", Spectrum(0.25f)), tex.spectrumTex(p, "Ks", Spectrum(0.25f)),
            tex.spectrumTex(p, "reflect", Spectrum(0.5f)),
            tex.spectrumTex(p, "transmit", Spectrum(0.5f)), tex.floatTex(p, "roughness", 0.1f),
            remap, bump);
    } else if (t == "mix") {
        std::vector<std::string> parts = p.getStrings("namedmaterial1");
        std::vector<std::string> parts2 = p.getStrings("namedmaterial2");
        const Material* ms[2] = {nullptr, nullptr};
        std::string wanted[2] = {parts.empty() ? "" : parts[0], parts2.empty() ? "" : parts2[0]};
        for (int i = 0; i < 2; ++i) {
            auto it = std::find(names.rbegin(), names.rend(), wanted[i]);
            if (wanted[i].empty() || it == names.rend()) {
                diag.error(e.loc, "mix material: undefined named material \"" + wanted[i] + "\"");
                *ok = false;
                return nullptr;
            }
            ms[i] = materials[size_t(names.rend() - it - 1)];
        }
        m = std::make_unique<MixMaterial>(ms[0], ms[1], tex.spectrumTex(p, "amount", Spectrum(0.5f)));
    } else if (t == "disney") {
        DisneyMaterial::Textures dt;
        dt.color = tex.spectrumTex(p, "color", Spectrum(0.5f));
        dt.metallic = tex.floatTex(p, "metallic", 0.f);
        dt.eta = tex.floatTex(p, "eta", 1.5f);
        dt.roughness = tex.floatTex(p, "roughness", 0.5f);
        dt.specularTint = tex.floatTex(p, "speculartint", 0.f);
        dt.anisotropic = tex.floatTex(p, "anisotropic", 0.f);
        dt.sheen = tex.floatTex(p, "sheen", 0.f);
        dt.sheenTint = tex.floatTex(p, "sheentint", 0.5f);
        dt.clearcoat = tex.floatTex(p, "clearcoat", 0.f);
        dt.clearcoatGloss = tex.floatTex(p, "clearcoatgloss", 1.f);
        dt.specTrans = tex.floatTex(p, "spectrans", 0.f);
        dt.scatterDistance = tex.spectrumTex(p, "scatterdistance", Spectrum(0.f));
        dt.thin = p.getBool("thin", false);
        dt.flatness = tex.floatTex(p, "flatness", 0.f);
        dt.diffTrans = tex.floatTex(p, "difftrans", 1.f);
        m = std::make_unique<DisneyMaterial>(std::move(dt), bump);
    } else if (t == "fourier") {
        auto table = std::make_shared<FourierTable>();
        std::string file = p.getFilename("bsdffile"), err;
        if (!readFourierTable(file, table.get(), &err)) {
            const Param* f = p.find("bsdffile");
            diag.substituted(f ? f->loc : e.loc,
                             (file.empty() ? std::string("fourier material without "
                                                         "\"bsdffile\"")
                                           : err) +
                                 "; the surface is black (as pbrt-v3)");
            table.reset();
        }
        m = std::make_unique<FourierMaterial>(std::move(table), bump);
    } else if (t == "hair") {
        m = createHairMaterial(e, tex, diag);
    } else if (t == "subsurface" || t == "kdsubsurface") {
        SubsurfaceMaterial::Textures st;
        st.kr = tex.spectrumTex(p, "Kr", Spectrum(1.f));
        st.kt = tex.spectrumTex(p, "Kt", Spectrum(1.f));
        st.u = tex.floatTex(p, "uroughness", 0.f);
        st.v = tex.floatTex(p, "vroughness", 0.f);
        st.remap = remap;
        st.eta = p.getFloat("eta", 1.33f);
        st.scale = p.getFloat("scale", 1.f);
        st.g = p.getFloat("g", 0.f);
        if (t == "kdsubsurface") {
            st.reflectance = tex.spectrumTex(p, "Kd", Spectrum(0.5f));
            st.mfp = tex.spectrumTex(p, "mfp", Spectrum(1.f));
        } else {
            // pbrt-v3's defaults: whole milk (mm^-1); a named measured medium replaces them
            // and forces g = 0 (the table holds reduced scattering coefficients).
            Spectrum sa(0.0011f, 0.0024f, 0.014f), ss(2.55f, 3.21f, 3.77f);
            const std::string name = p.getString("name", "");
            if (!name.empty()) {
                if (measuredSubsurface(name, &sa, &ss)) {
                    st.g = 0.f;
                } else {
                    const Param* np = p.find("name");
                    diag.substituted(np ? np->loc : e.loc,
                                     "subsurface material: unknown measured medium \"" + name +
                                         "\"; pbrt-v3's defaults (whole milk) are used");
                }
            }
            if (p.has("reflectance")) {
                // The reflectance / mean free path form (as kdsubsurface).
                st.reflectance = tex.spectrumTex(p, "reflectance", Spectrum(1.f));
                st.mfp = tex.spectrumTex(p, "mfp", Spectrum(1.f));
            } else {
                st.sigmaA = tex.spectrumTex(p, "sigma_a", sa);
                st.sigmaS = tex.spectrumTex(p, "sigma_s", ss);
            }
        }
        if (!(st.eta > 0.f)) {
            const Param* ep = p.find("eta");
            diag.error(ep ? ep->loc : e.loc, t + " material: \"eta\" must be positive");
            *ok = false;
            return nullptr;
        }
        m = std::make_unique<SubsurfaceMaterial>(std::move(st), bump);
    } else {
        // pbrt-v3 warns and makes a matte material from the same parameters.
        diag.substituted(e.loc, "unknown material type \"" + t +
                                    "\"; rendered as \"matte\" (as pbrt-v3)");
        m = std::make_unique<MatteMaterial>(tex.spectrumTex(p, "Kd", Spectrum(0.5f)),
                                            tex.floatTex(p, "sigma", 0.f), bump);
    }
    if (e.name.empty()) p.reportUnused("material \"" + t + "\"");
    else {
        if (const Param* tp = p.find("type")) tp->used = true;
        p.reportUnused("material \"" + e.name + "\"");
    }
    return m;
}

}  // namespace rlpbrt

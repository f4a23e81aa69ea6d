#include "converter/model_edit.hpp"

#include <tinyxml2.h>

#include <cstdio>

#include "converter/build/functions_to_core.hpp"
#include "converter/error.hpp"
#include "converter/osim_reader.hpp"

namespace redmax::osim {
namespace {

tinyxml2::XMLElement* findNamed(tinyxml2::XMLElement* e, const char* tag, const std::string& name) {
  for (; e; e = e->NextSiblingElement()) {
    const char* n = e->Attribute("name");
    if (std::string(e->Name()) == tag && n && name == n) return e;
    if (auto* c = findNamed(e->FirstChildElement(), tag, name)) return c;
  }
  return nullptr;
}

}  // namespace

JointTranslation::JointTranslation(const std::string& model_path, const std::string& joint) {
  const ModelDescription d = readOsimModel(model_path);
  for (const JointDesc& j : d.joints) {
    if (j.name != joint) continue;
    if (j.type != "CustomJoint") throw ConvertError(model_path, j.line, "joint '" + joint + "' is not a CustomJoint");
    for (int i = 0; i < 3; ++i) {
      const TransformAxisDesc& a = j.spatial_transform[3 + i];
      if (a.coordinates.size() != 1) continue;
      if ((a.axis - Vec3::Unit(i)).norm() > 1e-12)
        throw ConvertError(model_path, a.line, "joint '" + joint + "' " + a.name + ": axis is not the frame's");
      f_[i] = makeCoreFunction(a.function, 1, model_path, "CustomJoint '" + joint + "' " + a.name);
    }
    return;
  }
  throw ConvertError(model_path, 0, "no joint named '" + joint + "'");
}

Vec3 JointTranslation::at(double q) const {
  VecJ x(1);
  x[0] = q;
  Vec3 p = Vec3::Zero();
  for (int i = 0; i < 3; ++i)
    if (f_[i]) p[i] = f_[i]->value(x);
  return p;
}

std::string freezeJointTranslations(const std::string& model_path, const std::string& joint, double angle) {
  const JointTranslation t(model_path, joint);
  const Vec3 p = t.at(angle);
  tinyxml2::XMLDocument doc;
  if (doc.LoadFile(model_path.c_str()) != tinyxml2::XML_SUCCESS)
    throw ConvertError(model_path, doc.ErrorLineNum(), std::string("cannot parse: ") + doc.ErrorStr());
  tinyxml2::XMLElement* j = findNamed(doc.RootElement(), "CustomJoint", joint);
  if (!j) throw ConvertError(model_path, 0, "no CustomJoint named '" + joint + "'");
  for (int i = 0; i < 3; ++i) {
    if (!t.depends(i)) continue;
    const std::string axis = "translation" + std::to_string(i + 1);
    tinyxml2::XMLElement* a = findNamed(j->FirstChildElement(), "TransformAxis", axis);
    if (!a) throw ConvertError(model_path, j->GetLineNum(), "joint '" + joint + "' has no " + axis);
    // the function element is the axis's child named "function"
    tinyxml2::XMLElement* fn = nullptr;
    for (auto* c = a->FirstChildElement(); c; c = c->NextSiblingElement())
      if (c->Attribute("name") && std::string(c->Attribute("name")) == "function") fn = c;
    if (!fn) throw ConvertError(model_path, a->GetLineNum(), axis + " has no function");
    tinyxml2::XMLElement* k = doc.NewElement("Constant");
    k->SetAttribute("name", "function");
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.17g", p[i]);
    k->InsertNewChildElement("value")->SetText(buf);
    a->InsertAfterChild(fn, k);
    a->DeleteChild(fn);
    if (auto* c = a->FirstChildElement("coordinates")) c->SetText("");
  }
  tinyxml2::XMLPrinter pr;
  doc.Print(&pr);
  return pr.CStr();
}

}  // namespace redmax::osim

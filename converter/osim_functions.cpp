// OpenSim Function objects as data (semantics §4). Aliases are resolved as OpenSim registers them:
// NaturalCubicSpline and natCubicSpline are SimmSpline.
#include <set>

#include "converter/detail/osim_functions.hpp"

namespace redmax::osim::detail {
namespace {

std::vector<double> numbersOf(const XmlDocument& doc, const XMLElement* owner, const char* tag) {
  const XMLElement* c = firstChild(owner, tag);
  return c ? parseNumbers(doc, c) : std::vector<double>{};
}

// x/y tables shared by splines and piecewise functions
void readTable(const XmlDocument& doc, const XMLElement* e, FunctionDesc& f, size_t min_points) {
  f.x = numbersOf(doc, e, "x");
  f.y = numbersOf(doc, e, "y");
  if (f.x.size() != f.y.size())
    doc.fail(e, f.written_type + ": x has " + std::to_string(f.x.size()) + " values but y has " +
                    std::to_string(f.y.size()));
  if (f.x.size() < min_points)
    doc.fail(e, f.written_type + " needs at least " + std::to_string(min_points) +
                    " points, found " + std::to_string(f.x.size()));
}

}  // namespace

bool isFunctionTag(const std::string& tag) {
  static const std::set<std::string> tags = {
      "Constant",          "LinearFunction",      "PolynomialFunction",
      "SimmSpline",        "NaturalCubicSpline",  "natCubicSpline",
      "GCVSpline",         "MultiplierFunction",  "PiecewiseLinearFunction",
      "PiecewiseConstantFunction", "Sine",        "StepFunction",
      "MultivariatePolynomialFunction",           "ExpressionBasedFunction"};
  return tags.count(tag) > 0;
}

FunctionDesc parseFunction(const XmlDocument& doc, const XMLElement* e) {
  FunctionDesc f;
  f.written_type = e->Name();
  f.line = lineOf(e);
  const std::string& t = f.written_type;
  if (t == "Constant") {
    f.kind = FunctionKind::Constant;
    f.type = "Constant";
    f.value = childDouble(doc, e, "value", 0.0);
  } else if (t == "LinearFunction") {
    f.kind = FunctionKind::Linear;
    f.type = "LinearFunction";
    const XMLElement* c = firstChild(e, "coefficients");
    f.coefficients = c ? parseNumbers(doc, c) : std::vector<double>{1.0, 0.0};
    if (f.coefficients.empty()) doc.fail(c, "LinearFunction has no coefficients");
  } else if (t == "PolynomialFunction") {
    f.kind = FunctionKind::Polynomial;
    f.type = "PolynomialFunction";
    const XMLElement* c = firstChild(e, "coefficients");
    f.coefficients = c ? parseNumbers(doc, c) : std::vector<double>{1.0};
    if (f.coefficients.empty()) doc.fail(c, "PolynomialFunction has no coefficients");
  } else if (t == "SimmSpline" || t == "NaturalCubicSpline" || t == "natCubicSpline") {
    f.kind = FunctionKind::SimmSpline;
    f.type = "SimmSpline";
    readTable(doc, e, f, 2);
  } else if (t == "GCVSpline") {
    f.kind = FunctionKind::GCVSpline;
    f.type = "GCVSpline";
    const XMLElement* h = firstChild(e, "half_order");
    f.half_order = h ? parseInt(doc, h) : 0;
    if (f.half_order < 1 || f.half_order > 4)
      doc.fail(h ? h : e, "GCVSpline half_order must be 1..4, found " +
                              std::to_string(f.half_order));
    f.error_variance = childDouble(doc, e, "error_variance", 0.0);
    readTable(doc, e, f, static_cast<size_t>(2 * f.half_order));
    for (size_t i = 1; i < f.x.size(); ++i)
      if (!(f.x[i] > f.x[i - 1])) doc.fail(e, "GCVSpline x must be strictly increasing");
  } else if (t == "MultiplierFunction") {
    f.kind = FunctionKind::Multiplier;
    f.type = "MultiplierFunction";
    f.scale = childDouble(doc, e, "scale", 1.0);
    auto inner = findFunctionProperty(doc, e, "function");
    if (!inner) doc.fail(e, "MultiplierFunction has no function to scale");
    f.inner.push_back(std::move(*inner));
  } else if (t == "PiecewiseLinearFunction") {
    f.kind = FunctionKind::PiecewiseLinear;
    f.type = t;
    readTable(doc, e, f, 1);
  } else if (t == "PiecewiseConstantFunction") {
    f.kind = FunctionKind::PiecewiseConstant;
    f.type = t;
    readTable(doc, e, f, 1);
  } else if (t == "Sine") {
    f.kind = FunctionKind::Sine;
    f.type = t;
    f.amplitude = childDouble(doc, e, "amplitude", 1.0);
    f.omega = childDouble(doc, e, "omega", 1.0);
    f.phase = childDouble(doc, e, "phase", 0.0);
    f.offset = childDouble(doc, e, "offset", 0.0);
  } else if (t == "StepFunction") {
    f.kind = FunctionKind::Step;
    f.type = t;
    f.start_time = childDouble(doc, e, "transition_start_time", 0.99);
    f.end_time = childDouble(doc, e, "transition_end_time", 1.01);
    f.start_value = childDouble(doc, e, "start_value", 0.0);
    f.end_value = childDouble(doc, e, "end_value", 1.0);
  } else if (t == "MultivariatePolynomialFunction") {
    f.kind = FunctionKind::MultivariatePolynomial;
    f.type = t;
    const XMLElement* d = firstChild(e, "dimension");
    const XMLElement* o = firstChild(e, "order");
    f.dimension = d ? parseInt(doc, d) : 0;
    f.order = o ? parseInt(doc, o) : 0;
    f.coefficients = numbersOf(doc, e, "coefficients");
    if (f.dimension < 1 || f.dimension > 6)
      doc.fail(d ? d : e, "MultivariatePolynomialFunction dimension must be 1..6");
    if (f.order < 0) doc.fail(o ? o : e, "MultivariatePolynomialFunction order must be >= 0");
  } else if (t == "ExpressionBasedFunction") {
    f.kind = FunctionKind::ExpressionBased;
    f.type = t;
    f.expression = childText(e, "expression");
  } else {
    doc.fail(e, "unknown function type <" + t + ">");
  }
  return f;
}

std::optional<FunctionDesc> findFunctionProperty(const XmlDocument& doc, const XMLElement* owner,
                                                 const char* prop) {
  if (!owner) return std::nullopt;
  // wrapper form (pre-4.0): <prop><Type/></prop>
  if (const XMLElement* w = firstChild(owner, prop)) {
    const XMLElement* inner = w->FirstChildElement();
    if (!inner) return std::nullopt;
    return parseFunction(doc, inner);
  }
  // named form (4.0): <Type name="prop">
  for (const XMLElement* c : childElements(owner)) {
    if (attribute(c, "name") == prop && isFunctionTag(c->Name())) return parseFunction(doc, c);
  }
  // a named element of an unknown type is an error, not a silent default
  for (const XMLElement* c : childElements(owner)) {
    if (attribute(c, "name") == prop && std::string(c->Name()).find("Function") != std::string::npos)
      doc.fail(c, "unknown function type <" + std::string(c->Name()) + ">");
  }
  return std::nullopt;
}

}  // namespace redmax::osim::detail

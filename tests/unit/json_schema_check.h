// Checks JSON against a JSON Schema (draft 2020-12), for the keywords that
// engine/scene/scene.schema.json uses, so that tests need no validator package. A keyword it does
// not know is reported as an error, never skipped.
#pragma once

#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

namespace siviflow::testing {

class SchemaCheck {
 public:
  using Json = nlohmann::json;

  explicit SchemaCheck(Json root) : root_(std::move(root)) {}

  // Every way `value` breaks the schema, one line each, naming the JSON path ("" for the root).
  std::vector<std::string> errors(const Json& value) const {
    std::vector<std::string> out;
    std::set<std::string> evaluated;
    check(root_, value, "", &out, &evaluated);
    return out;
  }

 private:
  // "#/$defs/vec3" and the like: a JSON pointer into the root.
  const Json& resolve(const std::string& ref) const {
    return root_.at(Json::json_pointer(ref.substr(1)));
  }

  static bool has_type(const Json& value, const std::string& type) {
    if (type == "object") return value.is_object();
    if (type == "array") return value.is_array();
    if (type == "string") return value.is_string();
    if (type == "boolean") return value.is_boolean();
    if (type == "number") return value.is_number();
    if (type == "integer") {
      return value.is_number_integer() ||
             (value.is_number_float() &&
              value.get<double>() == static_cast<double>(value.get<long long>()));
    }
    return false;
  }

  // Checks `value` at `path` against `schema`, adding to `evaluated` the properties of `value`
  // that `schema` (and the schemas it applies in place: $ref, oneOf) evaluated.
  void check(const Json& schema, const Json& value, const std::string& path,
             std::vector<std::string>* out, std::set<std::string>* evaluated) const {
    const auto fail = [&](const std::string& what) { out->push_back(path + ": " + what); };
    for (const auto& [keyword, rule] : schema.items()) {
      if (keyword == "$schema" || keyword == "title" || keyword == "description" ||
          keyword == "default" || keyword == "$defs" || keyword == "unevaluatedProperties") {
        continue;  // annotations; unevaluatedProperties once the rest is known, below
      } else if (keyword == "$ref") {
        check(resolve(rule.get<std::string>()), value, path, out, evaluated);
      } else if (keyword == "type") {
        if (!has_type(value, rule.get<std::string>())) fail("not of type " + rule.dump());
      } else if (keyword == "const") {
        if (value != rule) fail("is not " + rule.dump());
      } else if (keyword == "enum") {
        if (std::find(rule.begin(), rule.end(), value) == rule.end())
          fail("not one of " + rule.dump());
      } else if (keyword == "properties") {
        if (!value.is_object()) continue;
        for (const auto& [key, sub] : rule.items()) {
          if (!value.contains(key)) continue;
          std::set<std::string> inner;
          check(sub, value[key], path + "." + key, out, &inner);
          evaluated->insert(key);
        }
      } else if (keyword == "additionalProperties") {
        if (!value.is_object()) continue;
        for (const auto& [key, item] : value.items()) {
          if (schema.contains("properties") && schema["properties"].contains(key)) continue;
          if (rule.is_boolean()) {
            if (!rule.get<bool>()) fail("key '" + key + "' is not allowed");
          } else {
            std::set<std::string> inner;
            check(rule, item, path + "." + key, out, &inner);
          }
          evaluated->insert(key);
        }
      } else if (keyword == "required") {
        if (!value.is_object()) continue;
        for (const Json& key : rule) {
          if (!value.contains(key.get<std::string>()))
            fail("'" + key.get<std::string>() + "' is required");
        }
      } else if (keyword == "items") {
        if (!value.is_array()) continue;
        for (size_t i = 0; i < value.size(); ++i) {
          std::set<std::string> inner;
          check(rule, value[i], path + "[" + std::to_string(i) + "]", out, &inner);
        }
      } else if (keyword == "minItems" || keyword == "maxItems") {
        if (!value.is_array()) continue;
        const bool low = keyword == "minItems";
        if (low ? value.size() < rule.get<size_t>() : value.size() > rule.get<size_t>()) {
          fail(keyword + " " + rule.dump());
        }
      } else if (keyword == "minLength") {
        if (value.is_string() && value.get<std::string>().size() < rule.get<size_t>()) {
          fail("shorter than " + rule.dump());
        }
      } else if (keyword == "minimum" || keyword == "maximum" || keyword == "exclusiveMinimum" ||
                 keyword == "exclusiveMaximum") {
        if (!value.is_number()) continue;
        const double v = value.get<double>();
        const double limit = rule.get<double>();
        const bool ok = keyword == "minimum"            ? v >= limit
                        : keyword == "maximum"          ? v <= limit
                        : keyword == "exclusiveMinimum" ? v > limit
                                                        : v < limit;
        if (!ok) fail(value.dump() + " breaks " + keyword + " " + rule.dump());
      } else if (keyword == "oneOf") {
        size_t matched = 0;
        std::set<std::string> matched_evaluated;
        for (const Json& sub : rule) {
          std::vector<std::string> sub_errors;
          std::set<std::string> sub_evaluated;
          check(sub, value, path, &sub_errors, &sub_evaluated);
          if (!sub_errors.empty()) continue;
          ++matched;
          matched_evaluated = std::move(sub_evaluated);
        }
        if (matched != 1) {
          fail("matches " + std::to_string(matched) + " of the " + std::to_string(rule.size()) +
               " schemas of oneOf (one is required)");
        } else {
          evaluated->insert(matched_evaluated.begin(), matched_evaluated.end());
        }
      } else if (keyword == "not") {
        std::vector<std::string> sub_errors;
        std::set<std::string> sub_evaluated;
        check(rule, value, path, &sub_errors, &sub_evaluated);
        if (sub_errors.empty()) fail("matches what 'not' forbids: " + rule.dump());
      } else {
        fail("the schema uses '" + keyword + "', which this checker does not know");
      }
    }
    if (schema.contains("unevaluatedProperties") && value.is_object()) {
      if (schema["unevaluatedProperties"] != false) {
        fail("the schema's unevaluatedProperties is not false, which this checker does not know");
      }
      for (const auto& [key, item] : value.items()) {
        if (evaluated->count(key) == 0) fail("key '" + key + "' is not allowed");
      }
    }
  }

  Json root_;
};

}  // namespace siviflow::testing

// The BVH reader (paper §5: real head motion) on a hand-made skeleton with known answers, on
// every kind of malformed file (STYLE.md §6), and on the CMU recordings Debian ships.
#include "qvr/trace/bvh.h"

#include <cmath>
#include <filesystem>
#include <random>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "qvr/trace/head_motion.h"

namespace qvr {
namespace {

using ::testing::HasSubstr;

// Hips → Spine → Head, and one leg whose end site touches the floor. Centimetres. Channel
// orders differ per joint on purpose. Columns: root 0–5 (Xp Yp Zp Zr Xr Yr), Spine 6–8
// (Zr Xr Yr), Head 9–11 (Xr Yr Zr), LeftLeg 12–14 (Zr Xr Yr).
constexpr const char* kHierarchy = R"(HIERARCHY
ROOT Hips
{
	OFFSET 0 0 0
	CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
	JOINT Spine
	{
		OFFSET 0 50 0
		CHANNELS 3 Zrotation Xrotation Yrotation
		JOINT Head
		{
			OFFSET 0 60 0
			CHANNELS 3 Xrotation Yrotation Zrotation
			End Site
			{
				OFFSET 0 10 0
			}
		}
	}
	JOINT LeftLeg
	{
		OFFSET 10 0 0
		CHANNELS 3 Zrotation Xrotation Yrotation
		End Site
		{
			OFFSET 0 -90 0
		}
	}
}
)";

std::string smallBvh() {
    return std::string(kHierarchy) +
           "MOTION\n"
           "Frames: 5\n"
           "Frame Time: 0.1\n"
           "0 90 0 0 0 0 0 0 0 0 0 0 0 0 0\n"     // 0: standing
           "0 90 0 0 0 90 0 0 0 0 0 0 0 0 0\n"    // 1: whole body turned +90° about y
           "0 90 0 0 0 0 0 45 0 0 0 0 0 0 0\n"    // 2: bent forward 45° at the spine
           "0 90 0 0 0 0 0 0 0 90 90 0 0 0 0\n"   // 3: head X then Y, 90° each
           "12 90 -8 0 0 0 0 0 0 0 0 0 0 0 0\n";  // 4: stepped 12 cm in x, 8 cm in −z
}

HeadMotionOptions exactOptions() {
    HeadMotionOptions o;
    o.unit = BvhUnit::kCentimetre;
    o.eye_offset_m = glm::vec3(0.0f);
    o.drop_reference_frame = false;
    return o;
}

void expectNear(const glm::vec3& a, const glm::vec3& b, float tol = 1e-4f) {
    EXPECT_NEAR(a.x, b.x, tol);
    EXPECT_NEAR(a.y, b.y, tol);
    EXPECT_NEAR(a.z, b.z, tol);
}

TEST(BvhReader, ReadsTheHierarchyAndFrames) {
    auto m = parseBvh(smallBvh(), "small.bvh");
    ASSERT_TRUE(m.ok()) << m.error();
    ASSERT_EQ(m->joints.size(), 4u);
    EXPECT_EQ(m->joints[0].name, "Hips");
    EXPECT_EQ(m->joints[2].name, "Head");
    EXPECT_EQ(m->joints[2].parent, 1);
    EXPECT_EQ(m->joints[3].parent, 0);
    EXPECT_EQ(m->channel_count, 15);
    EXPECT_EQ(m->joints[2].first_channel, 9);
    EXPECT_EQ(m->joints[2].channels[0], BvhChannel::kXrot);
    EXPECT_TRUE(m->joints[2].has_end_site);
    EXPECT_EQ(m->frame_count, 5);
    EXPECT_DOUBLE_EQ(m->frame_time_s, 0.1);
    EXPECT_DOUBLE_EQ(m->frame(4)[0], 12.0);
    EXPECT_DOUBLE_EQ(m->frame(4)[2], -8.0);
}

TEST(HeadMotion, ForwardKinematicsGivesTheKnownHeadPoses) {
    auto m = parseBvh(smallBvh(), "small.bvh");
    ASSERT_TRUE(m.ok()) << m.error();
    auto poses = headPosesFromBvh(*m, exactOptions());
    ASSERT_TRUE(poses.ok()) << poses.error();
    ASSERT_EQ(poses->samples.size(), 5u);
    const auto& s = poses->samples;
    // Standing: head at 90 + 50 + 60 cm above the foot's end site, looking ahead (−z in qvr).
    expectNear(s[0].pose.position_m, {0.0f, 2.0f, 0.0f});
    EXPECT_LT(angleBetweenDeg(s[0].pose.orientation, glm::quat(1, 0, 0, 0)), 1e-3);
    // Turned +90° about y: the same yaw in qvr's frame (the half turn commutes with it).
    EXPECT_NEAR(eulerDegFromQuat(s[1].pose.orientation).yaw_deg, 90.0, 1e-3);
    expectNear(s[1].pose.position_m, {0.0f, 2.0f, 0.0f});
    // Bent forward 45°: head forward of the hips (BVH +z is qvr −z) and looking down 45°.
    expectNear(s[2].pose.position_m,
               {0.0f, 1.4f + 0.6f * std::cos(0.785398163f), -0.6f * std::sin(0.785398163f)});
    EXPECT_NEAR(eulerDegFromQuat(s[2].pose.orientation).pitch_deg, -45.0, 1e-3);
    // Head channels "X Y Z" compose as Rx·Ry: BVH forward +z → +x, i.e. qvr −x (yaw +90°).
    const glm::vec3 fwd = s[3].pose.orientation * glm::vec3(0, 0, -1);
    expectNear(fwd, {-1.0f, 0.0f, 0.0f});
    // Root position channels add to the offset; BVH x and z flip sign in qvr.
    expectNear(s[4].pose.position_m, {-0.12f, 2.0f, 0.08f});
    EXPECT_DOUBLE_EQ(s[4].t_ms, 400.0);
}

TEST(HeadMotion, EyeOffsetFollowsTheHead) {
    auto m = parseBvh(smallBvh(), "small.bvh");
    ASSERT_TRUE(m.ok());
    HeadMotionOptions o = exactOptions();
    o.eye_offset_m = {0.0f, 0.1f, -0.1f};
    auto poses = headPosesFromBvh(*m, o);
    ASSERT_TRUE(poses.ok());
    expectNear(poses->samples[0].pose.position_m, {0.0f, 2.1f, -0.1f});
    // Turned +90° (looking along qvr −x): the eyes sit 10 cm toward −x.
    expectNear(poses->samples[1].pose.position_m, {-0.1f, 2.1f, 0.0f});
}

TEST(HeadMotion, ResamplesPlacesAndPicksUnits) {
    auto m = parseBvh(smallBvh(), "small.bvh");
    ASSERT_TRUE(m.ok());
    EXPECT_EQ(detectBvhUnit(*m), BvhUnit::kCentimetre);  // 2.1 units tall: cm, not inches
    HeadMotionOptions o = exactOptions();
    o.rate_hz = 20.0;  // 50 ms steps: every other sample is a slerp midpoint
    o.origin_m = {5.0f, 1.0f, -3.0f};
    o.yaw_deg = 30.0;
    auto t = headTraceFromBvh(*m, o);
    ASSERT_TRUE(t.ok()) << t.error();
    ASSERT_EQ(t->samples.size(), 9u);  // 0..400 ms
    EXPECT_DOUBLE_EQ(t->samples[1].t_ms, 50.0);
    expectNear(t->samples[0].pose.position_m, {5.0f, 3.0f, -3.0f});
    EXPECT_NEAR(eulerDegFromQuat(t->samples[0].pose.orientation).yaw_deg, 30.0, 1e-3);
    // Midway through the 90° turn: 45° more than the start.
    EXPECT_NEAR(eulerDegFromQuat(t->samples[1].pose.orientation).yaw_deg, 75.0, 1e-2);
    o.frames = 10;
    EXPECT_FALSE(headTraceFromBvh(*m, o).ok()) << "more frames than the recording holds";
}

TEST(HeadMotion, NamesParsesAndSizesEveryUnit) {
    for (BvhUnit unit : {BvhUnit::kAuto, BvhUnit::kMetre, BvhUnit::kCentimetre, BvhUnit::kInch,
                         BvhUnit::kCmuAsf}) {
        auto back = bvhUnitFromName(bvhUnitName(unit));
        ASSERT_TRUE(back.ok()) << bvhUnitName(unit);
        EXPECT_EQ(*back, unit);
    }
    EXPECT_EQ(bvhUnitMetres(BvhUnit::kAuto), 0.0);
    EXPECT_EQ(bvhUnitMetres(BvhUnit::kCentimetre), 0.01);
    EXPECT_DOUBLE_EQ(bvhUnitMetres(BvhUnit::kCmuAsf), 0.0254 / 0.45);
    auto bad = bvhUnitFromName("feet");
    ASSERT_FALSE(bad.ok());
    EXPECT_EQ(bad.error(), "unit 'feet': expected auto, m, cm, inch or cmu");
}

TEST(HeadMotion, FindsTheHeadByNameOrAsTheTopOfTheSpine) {
    auto m = parseBvh(smallBvh(), "small.bvh");
    ASSERT_TRUE(m.ok());
    EXPECT_EQ(*findHeadJoint(*m, ""), 2);
    EXPECT_EQ(*findHeadJoint(*m, "Spine"), 1);
    EXPECT_FALSE(findHeadJoint(*m, "Tail").ok());
    std::string renamed = smallBvh();
    renamed.replace(renamed.find("JOINT Head"), 10, "JOINT Skull");
    auto r = parseBvh(renamed, "renamed.bvh");
    ASSERT_TRUE(r.ok());
    EXPECT_EQ(*findHeadJoint(*r, ""), 2);
}

TEST(HeadMotion, DropsAReferencePoseFirstFrame) {
    auto m = parseBvh(smallBvh(), "small.bvh");
    ASSERT_TRUE(m.ok());
    // Frames 0→1 turn 90° in one frame, far more than 5°: the rule takes frame 0 for a
    // reference pose and drops it.
    HeadMotionOptions o = exactOptions();
    o.drop_reference_frame = true;
    auto dropped = headPosesFromBvh(*m, o);
    ASSERT_TRUE(dropped.ok());
    EXPECT_EQ(dropped->samples.size(), 4u);
    EXPECT_DOUBLE_EQ(dropped->samples[0].t_ms, 0.0);
    EXPECT_NEAR(eulerDegFromQuat(dropped->samples[0].pose.orientation).yaw_deg, 90.0, 1e-3);
}

struct Malformed {
    const char* what;
    std::string text;
    const char* message;
};

std::string replaced(std::string s, const std::string& from, const std::string& to) {
    const size_t at = s.find(from);
    QVR_CHECK(at != std::string::npos);
    return s.replace(at, from.size(), to);
}

TEST(BvhReader, RejectsEachMalformedFileWithALineNumber) {
    const std::string good = smallBvh();
    const std::vector<Malformed> cases = {
        {"empty", "", "expected HIERARCHY"},
        {"missing MOTION", kHierarchy, "missing MOTION"},
        {"wrong word for MOTION", std::string(kHierarchy) + "MOTON\nFrames: 1\n",
         "expected MOTION"},
        {"short frame", replaced(good, "0 90 0 0 0 90 0 0 0 0 0 0 0 0 0\n", "0 90 0 0 0 90 0\n"),
         "small.bvh:34: frame 1: 7 values, the hierarchy's CHANNELS declare 15"},
        {"long frame",
         replaced(good, "0 90 0 0 0 0 0 0 0 0 0 0 0 0 0\n", "0 90 0 0 0 0 0 0 0 0 0 0 0 0 0 5\n"),
         "small.bvh:33: frame 0: more than the 15 values"},
        {"non-numeric value", replaced(good, "12 90 -8", "12 ninety -8"),
         "small.bvh:37: frame 4: value 2 'ninety'"},
        {"nan value", replaced(good, "12 90 -8", "12 nan -8"), "is not a number"},
        {"non-numeric offset", replaced(good, "OFFSET 0 50 0", "OFFSET 0 fifty 0"),
         "small.bvh:8: OFFSET value 'fifty'"},
        {"channel count 7", replaced(good, "CHANNELS 6", "CHANNELS 7"),
         "small.bvh:5: CHANNELS count '7' is not 0 to 6"},
        {"channel count 9", replaced(good, "CHANNELS 6", "CHANNELS 9"),
         "small.bvh:5: CHANNELS count '9'"},
        {"channel count too small", replaced(good, "CHANNELS 6", "CHANNELS 5"),
         "small.bvh:5: expected JOINT"},
        {"unknown channel",
         replaced(good, "Zrotation Xrotation Yrotation\n\t\tJOINT",
                  "Zrotation Wrotation Yrotation\n\t\tJOINT"),
         "small.bvh:9: 'Wrotation' is not a channel name"},
        {"repeated channel",
         replaced(good, "CHANNELS 3 Xrotation Yrotation Zrotation",
                  "CHANNELS 3 Xrotation Xrotation Zrotation"),
         "small.bvh:13: channel Xrotation listed twice"},
        {"truncated frames", replaced(good, "Frames: 5", "Frames: 7"),
         "truncated: Frames: says 7, file holds 5"},
        {"truncated hierarchy", good.substr(0, good.find("JOINT LeftLeg")),
         "file ends inside joint"},
        {"truncated mid-offset", good.substr(0, good.find("OFFSET 0 60") + 9),
         "file ends inside OFFSET"},
        {"frames not a number", replaced(good, "Frames: 5", "Frames: five"),
         "small.bvh:31: 'Frames:' needs a number"},
        {"zero frames", replaced(good, "Frames: 5", "Frames: 0"), "not a whole number"},
        {"bad frame time", replaced(good, "Frame Time: 0.1", "Frame Time: -1"),
         "small.bvh:32: Frame Time"},
        {"garbage after frames", good + "hello\n", "data after the 5 frames"},
        {"two roots", std::string(kHierarchy) + "ROOT Again\n", "more than one ROOT"},
        {"binary", std::string("\x01\x02\xff\x00HIER", 8), "expected HIERARCHY"},
    };
    for (const auto& c : cases) {
        auto r = parseBvh(c.text, "small.bvh");
        ASSERT_FALSE(r.ok()) << c.what;
        EXPECT_THAT(r.error(), HasSubstr(c.message)) << c.what;
        EXPECT_THAT(r.error(), HasSubstr("small.bvh:")) << c.what;
    }
}

TEST(BvhReader, EnforcesItsLimits) {
    const std::string good = smallBvh();
    BvhLimits few_frames;
    few_frames.max_frames = 4;
    auto r = parseBvh(good, "small.bvh", few_frames);
    ASSERT_FALSE(r.ok());
    EXPECT_THAT(r.error(), HasSubstr("[1, 4]"));
    BvhLimits few_joints;
    few_joints.max_joints = 3;
    r = parseBvh(good, "small.bvh", few_joints);
    ASSERT_FALSE(r.ok());
    EXPECT_THAT(r.error(), HasSubstr("more than 3 joints"));
    BvhLimits few_values;
    few_values.max_values = 70;
    r = parseBvh(good, "small.bvh", few_values);
    ASSERT_FALSE(r.ok());
    EXPECT_THAT(r.error(), HasSubstr("exceeds 70 values"));
    BvhLimits small_file;
    small_file.max_bytes = 100;
    EXPECT_FALSE(parseBvh(good, "small.bvh", small_file).ok());
    // A declared frame count far beyond the data: no huge allocation, just "truncated".
    r = parseBvh(replaced(good, "Frames: 5", "Frames: 1000000"), "small.bvh");
    ASSERT_FALSE(r.ok());
    EXPECT_THAT(r.error(), HasSubstr("truncated"));
    // Deep nesting.
    std::string deep = "HIERARCHY\nROOT r\n{\nOFFSET 0 0 0\nCHANNELS 0\n";
    for (int i = 0; i < 100; ++i)
        deep += "JOINT j\n{\nOFFSET 0 1 0\nCHANNELS 0\n";
    r = parseBvh(deep, "deep.bvh");
    ASSERT_FALSE(r.ok());
    EXPECT_THAT(r.error(), HasSubstr("deeper than 64"));
}

TEST(BvhReader, SurvivesRandomTruncationAndMutation) {
    const std::string good = smallBvh();
    for (size_t n = 0; n + 1 < good.size(); ++n)  // the final newline is optional
        EXPECT_FALSE(parseBvh(good.substr(0, n), "cut.bvh").ok()) << n;
    std::mt19937 rng(3);
    std::uniform_int_distribution<size_t> pos(0, good.size() - 1);
    std::uniform_int_distribution<int> byte(0, 255);
    int parsed = 0;
    for (int trial = 0; trial < 2000; ++trial) {
        std::string s = good;
        for (int k = 0; k < 3; ++k)
            s[pos(rng)] = static_cast<char>(byte(rng));
        auto r = parseBvh(s, "mutated.bvh");
        if (r.ok()) {
            ++parsed;  // a harmless mutation (e.g. inside a name): FK must still work
            auto poses = headPosesFromBvh(*r, exactOptions());
            (void)poses;
        }
    }
    EXPECT_LT(parsed, 2000);
}

const char* kCmuDir = "/usr/share/assimp/models/BVH/";

TEST(BvhReader, ReadsTheCmuRecordingsOfAssimpTestmodels) {
    const std::string path = std::string(kCmuDir) + "01_01.bvh";
    if (!std::filesystem::exists(path))
        GTEST_SKIP() << path << " absent (Debian package assimp-testmodels)";
    auto m = loadBvhFile(path);
    ASSERT_TRUE(m.ok()) << m.error();
    EXPECT_EQ(m->joints.size(), 31u);
    EXPECT_EQ(m->channel_count, 96);
    EXPECT_EQ(m->frame_count, 2752);
    EXPECT_NEAR(m->frame_time_s, 1.0 / 120.0, 1e-6);
    EXPECT_EQ(detectBvhUnit(*m), BvhUnit::kCmuAsf);
    EXPECT_EQ(m->joints[static_cast<size_t>(*findHeadJoint(*m, ""))].name, "Head");
    HeadMotionOptions o;
    o.frames = 900;  // 10 s at 90 Hz
    auto t = headTraceFromBvh(*m, o);
    ASSERT_TRUE(t.ok()) << t.error();
    ASSERT_EQ(t->samples.size(), 900u);
    // A person's eyes: 1.3–1.6 m above the floor most of the time (the subject crouches and
    // jumps: 0.9–2 m always); the head turning at human speeds.
    std::vector<double> speeds;
    std::vector<float> heights;
    for (size_t i = 0; i < t->samples.size(); ++i) {
        heights.push_back(t->samples[i].pose.position_m.y);
        EXPECT_GT(heights.back(), 0.9f);
        EXPECT_LT(heights.back(), 2.0f);
        if (i > 0)
            speeds.push_back(angleBetweenDeg(t->samples[i - 1].pose.orientation,
                                             t->samples[i].pose.orientation) *
                             90.0);
    }
    std::sort(heights.begin(), heights.end());
    EXPECT_GT(heights[heights.size() / 2], 1.3f);
    EXPECT_LT(heights[heights.size() / 2], 1.6f);
    std::sort(speeds.begin(), speeds.end());
    EXPECT_LT(speeds[speeds.size() / 2], 150.0);
    EXPECT_LT(speeds.back(), 1000.0) << "the reference pose of frame 0 was not dropped";

    const std::string boxing = std::string(kCmuDir) + "Boxing_Toes.bvh";
    if (std::filesystem::exists(boxing)) {
        auto b = loadBvhFile(boxing);
        ASSERT_TRUE(b.ok()) << b.error();
        EXPECT_EQ(b->ignored_frames, 1) << "the file holds one frame more than it declares";
        EXPECT_EQ(detectBvhUnit(*b), BvhUnit::kCentimetre);
    }
}

}  // namespace
}  // namespace qvr

<?xml version="1.0" encoding="utf-8"?>
<!DOCTYPE TS>
<TS version="2.1">
<context>
    <name>AlgorithmBase</name>
    <message>
        <location filename="../processing_provider/base.py" line="78"/>
        <source>Cancelled: {}</source>
        <translation type="unfinished"></translation>
    </message>
</context>
<context>
    <name>AlignImagesAlgorithm</name>
    <message>
        <location filename="../processing_provider/align_images.py" line="48"/>
        <source>Folder of images</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="50"/>
        <source>Workspace folder</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="51"/>
        <source>Pair selection</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="53"/>
        <source>Camera model</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="55"/>
        <source>Largest image side for matching (0 = full size)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="58"/>
        <source>Largest number of features per image (0 = auto, ~4000 per megapixel)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="61"/>
        <source>Affine-invariant features (oblique views; slower)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="63"/>
        <source>Focal length in mm when EXIF is missing (0 = from EXIF)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="66"/>
        <source>Sensor (frame) width in mm, long side (0 = unknown)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="69"/>
        <source>One camera for all images</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="71"/>
        <source>Camera centres</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="72"/>
        <source>Registered images</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="73"/>
        <source>Mean reprojection error (px)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="95"/>
        <source>Registered {} of {} images, mean reprojection error {:.3f} px, {} points</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="98"/>
        <source>Images not registered:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="101"/>
        <source>Seconds per step: {}</source>
        <translation type="unfinished"></translation>
    </message>
</context>
<context>
    <name>ArchaeoOrthoProvider</name>
    <message>
        <location filename="../processing_provider/provider.py" line="17"/>
        <source>ArchaeoOrtho photogrammetry</source>
        <translation type="unfinished"></translation>
    </message>
</context>
</TS>
